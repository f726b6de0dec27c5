#pragma once
#include <behaviortree_cpp/action_node.h>

namespace pkg
{
// A project base in a header of its own; its derived classes live in src/.
template <class ServiceT>
class ServiceNode : public BT::ActionNodeBase
{
public:
  static BT::PortsList providedBasicPorts(BT::PortsList addition)
  {
    BT::PortsList basic = { BT::InputPort<std::string>("service_name", "Service to call"),
                            BT::OutputPort<typename ServiceT::Response>("response") };
    basic.insert(addition.begin(), addition.end());
    return basic;
  }
  static BT::PortsList providedPorts() { return providedBasicPorts({}); }
};

template <typename T>
class GetValue : public BT::SyncActionNode
{
public:
  static BT::PortsList providedPorts() { return { BT::OutputPort<T>("value") }; }
};
}  // namespace pkg
