#include "nodes.hpp"

namespace arm
{
BT::PortsList Setup::providedPorts()
{
  return { BT::InputPort<std::string>("group_name") };
}

BT::PortsList Twice::providedPorts() { return { BT::InputPort<int>("a") }; }
}  // namespace arm
