#include "wrapper.hpp"

namespace demo
{
class Abort : public BT::SyncActionNode
{
public:
  static BT::PortsList providedPorts() { return {}; }
};

class DelayFor : public BT::DecoratorNode
{
public:
  static BT::PortsList providedPorts()
  {
    return { BT::InputPort<unsigned>("delay_msec") };
  }
};

class Move : public BT::StatefulActionNode
{
public:
  static BT::PortsList providedPorts() { return { BT::InputPort<double>("speed", 1.5, "") }; }
};
}  // namespace demo

BT_REGISTER_NODES(factory)
{
  factory.registerNodeType<demo::Logged<demo::Abort>>("Abort");
  factory.registerNodeType<demo::Logged<demo::DelayFor>>("DelayFor");
  factory.registerNodeType<demo::WithTimeout<demo::Logged<demo::Move>>>("Move");
}
