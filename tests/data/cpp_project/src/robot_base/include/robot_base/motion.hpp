#pragma once
#include <behaviortree_cpp/action_node.h>

namespace robot_base
{
// Every motion node takes a speed limit; derived classes add their own ports.
class MotionNode : public BT::StatefulActionNode
{
public:
  static BT::PortsList providedBasicPorts(BT::PortsList addition)
  {
    BT::PortsList basic = { BT::InputPort<double>("max_speed", 0.5, "Speed limit in m/s") };
    basic.insert(addition.begin(), addition.end());
    return basic;
  }
};
}  // namespace robot_base
