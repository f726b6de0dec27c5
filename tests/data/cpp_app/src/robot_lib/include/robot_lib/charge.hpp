#pragma once
#include <behaviortree_cpp/bt_factory.h>

namespace robot_lib
{
class Charge : public BT::SyncActionNode
{
public:
  Charge(const std::string& name, const BT::NodeConfig& config) : BT::SyncActionNode(name, config) {}
  static BT::PortsList providedPorts()
  {
    return { BT::InputPort<int>("until_percent", 90, "Charge up to this level") };
  }
  BT::NodeStatus tick() override { return BT::NodeStatus::SUCCESS; }
};

// Port lists built by code: what they hold is not known without running it.
BT::PortsList scanPorts();

class Scan : public BT::SyncActionNode
{
public:
  Scan(const std::string& name, const BT::NodeConfig& config) : BT::SyncActionNode(name, config) {}
  static BT::PortsList providedPorts() { return scanPorts(); }
  BT::NodeStatus tick() override { return BT::NodeStatus::SUCCESS; }
};

void registerNodes(BT::BehaviorTreeFactory& factory);
}  // namespace robot_lib
