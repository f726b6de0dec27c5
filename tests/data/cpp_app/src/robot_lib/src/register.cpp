#include "robot_lib/charge.hpp"

namespace robot_lib
{
void registerNodes(BT::BehaviorTreeFactory& factory)
{
  factory.registerNodeType<Charge>("Charge");
  factory.registerNodeType<Scan>("Scan");
}
}  // namespace robot_lib
