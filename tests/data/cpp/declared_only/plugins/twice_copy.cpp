#include "nodes.hpp"

BT::PortsList arm::Twice::providedPorts() { return { BT::InputPort<int>("b") }; }
