#include "base.hpp"

BT::PortsList Task::providedPorts()
{
  auto ports = MoveBase::providedPorts();
  ports.emplace(BT::InputPort<int>("priority", 0, "higher first"));
  ports.insert(BT::InputPort<int>("speed", 9, "an existing key wins"));
  return ports;
}

BT_REGISTER_NODES(factory)
{
  factory.registerNodeType<Task>("Task");
  factory.registerNodeType<Alias>("Alias");
  factory.registerNodeType<Inherits>("Inherits");
}
