#include <behaviortree_cpp/bt_factory.h>
#include <nav2_behavior_tree/bt_action_node.hpp>
#include <vendor/base.hpp>

class Wait : public BT::SyncActionNode
{
public:
  static BT::PortsList providedPorts()
  {
    return { BT::InputPort<double>("timeout", std::numeric_limits<double>::infinity(), "never") };
  }
};

// The base comes from a package that is not read.
class Vendored : public vendor::FancyAction
{
public:
  static BT::PortsList providedPorts() { return { BT::InputPort<int>("x") }; }
};

// The ports are built by a helper that is not read.
class Built : public BT::SyncActionNode
{
public:
  static BT::PortsList providedPorts() { return makePorts<Built>(); }
};

// Nav2's bases give the kind; their basic ports depend on the Nav2 release.
class Spin : public nav2_behavior_tree::BtActionNode<nav2_msgs::action::Spin>
{
public:
  static BT::PortsList providedPorts()
  {
    return providedBasicPorts({ BT::InputPort<double>("spin_dist", 1.57, "Spin distance") });
  }
};

class Twin : public BT::SyncActionNode
{
public:
  static BT::PortsList providedPorts() { return {}; }
};

// Another class under the same ID: which one a program registers is not known.
class OtherTwin : public BT::SyncActionNode
{
public:
  static BT::PortsList providedPorts() { return {}; }
};

template <class T>
void registerLater(BT::BehaviorTreeFactory& factory, const std::string& name)
{
  factory.registerNodeType<T>(name);
}

BT_REGISTER_NODES(factory)
{
  factory.registerNodeType<Wait>("Wait");
  factory.registerNodeType<Vendored>("Vendored");
  factory.registerNodeType<Built>("Built");
  factory.registerNodeType<Spin>("Spin");
  factory.registerNodeType<Twin>("Twin");
  factory.registerNodeType<OtherTwin>("Twin");
  factory.registerNodeType<Missing>("Missing");
  registerLater<Wait>(factory, computed_name);
}

// A helper that merges port lists with a loop: its result is not read, the lists given
// to it are kept (the list stays incomplete).
class Merged : public BT::SyncActionNode
{
public:
  static BT::PortsList providedPorts()
  {
    return appendPorts(Wait::providedPorts(), { BT::InputPort<int>("goal_x") });
  }
};

void registerMore(BT::BehaviorTreeFactory& factory)
{
  factory.registerNodeType<Merged>("Merged");
}
