#pragma once
#include <behaviortree_cpp/bt_factory.h>

class Dock : public BT::StatefulActionNode
{
public:
  static BT::PortsList providedPorts() { return { BT::InputPort<std::string>("station") }; }
};

class Undock : public BT::StatefulActionNode
{
public:
  static BT::PortsList providedPorts() { return {}; }
};
