#include <behaviortree_cpp/bt_factory.h>
#include "robot_nodes/nodes.hpp"

BT_REGISTER_NODES(factory)
{
  factory.registerNodeType<robot_nodes::DriveTo>("DriveTo");
  factory.registerNodeType<robot_nodes::BatteryOk>("BatteryOk");
}
