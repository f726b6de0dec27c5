#include "register_nodes.hpp"

namespace boat
{
class WaitAction : public BT::StatefulActionNode
{
public:
  static BT::PortsList providedPorts() { return { BT::InputPort<double>("duration") }; }
};
}  // namespace boat

REGISTER_NODES(boat, WaitAction)
