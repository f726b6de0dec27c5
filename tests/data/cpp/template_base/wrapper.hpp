#pragma once
#include <behaviortree_cpp/bt_factory.h>

namespace demo
{
// A wrapper that derives from its template argument: the node's kind and ports are
// those of the class it wraps.
template <class BaseNodeT, bool plain = false>
class Logged;

template <class BaseNodeT>
class Logged<BaseNodeT, false> : public BaseNodeT
{
public:
  using BaseNodeT::BaseNodeT;
  BT::NodeStatus executeTick() override { return BaseNodeT::executeTick(); }
};

// A base that adds to the ports of the class it wraps.
template <typename Inner>
class WithTimeout : public Inner
{
public:
  using Inner::Inner;
  static BT::PortsList providedPorts()
  {
    BT::PortsList ports = Inner::providedPorts();
    ports.insert(BT::InputPort<int>("timeout_ms"));
    return ports;
  }
};
}  // namespace demo
