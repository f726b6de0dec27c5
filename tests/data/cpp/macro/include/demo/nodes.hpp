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

class Charge : public BT::SyncActionNode
{
public:
  Charge(const std::string& name, const BT::NodeConfig& config, int rate);
  static BT::PortsList providedPorts() { return { BT::InputPort<int>("percent", 90, "Stop here") }; }
};
