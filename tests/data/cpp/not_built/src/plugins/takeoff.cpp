#include "takeoff.h"

BT::PortsList Takeoff::providedPorts()
{
  return { BT::InputPort<double>("goal"), BT::InputPort("is_rc") };
}

BT_REGISTER_NODES(factory)
{
  factory.registerNodeType<Takeoff>("Takeoff");
}
