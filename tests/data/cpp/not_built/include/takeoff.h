#pragma once
#include <behaviortree_cpp/action_node.h>

class Takeoff : public BT::SyncActionNode
{
public:
  Takeoff(const std::string& name, const BT::NodeConfig& config);
  static BT::PortsList providedPorts();
  BT::NodeStatus tick() override;
};
