#pragma once
#include <behaviortree_cpp/action_node.h>

namespace arm
{
// providedPorts is declared here and defined out of line in plugins/setup.cpp.
class Setup : public BT::SyncActionNode
{
public:
  static BT::PortsList providedPorts();
};

// Declared here, defined nowhere that was read: its ports are unknown, not "none".
class Unseen : public BT::SyncActionNode
{
public:
  static BT::PortsList providedPorts();
};

// Two definitions that differ (copies in two files): which is built is not known.
class Twice : public BT::SyncActionNode
{
public:
  static BT::PortsList providedPorts();
};

inline void RegisterNodes(BT::BehaviorTreeFactory& factory)
{
  factory.registerNodeType<Setup>("Setup");
  factory.registerNodeType<Unseen>("Unseen");
  factory.registerNodeType<Twice>("Twice");
}
}  // namespace arm
