#pragma once
#include <robot_base/motion.hpp>

namespace robot_nodes
{
class DriveTo : public robot_base::MotionNode
{
public:
  static BT::PortsList providedPorts()
  {
    return providedBasicPorts({ BT::InputPort<std::string>("target", "Named place to drive to"),
                                BT::OutputPort<double>("distance", "Distance driven") });
  }
};

class BatteryOk : public BT::ConditionNode
{
public:
  static BT::PortsList providedPorts()
  {
    return { BT::InputPort<int>("min_percent", 20, "Lowest acceptable charge") };
  }
};
}  // namespace robot_nodes
