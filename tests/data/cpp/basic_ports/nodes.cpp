#include <behaviortree_ros2/bt_action_node.hpp>
#include <other_pkg/base.hpp>

// The base comes from another package that is not read: its basic ports are unknown, the
// node's own are kept.
class Grip : public other_pkg::GripperBase<Gripper>
{
public:
  static BT::PortsList providedPorts()
  {
    return providedBasicPorts({ BT::InputPort<double>("force", 10, "newton") });
  }
};

// A base bt-lsp knows (BehaviorTree.ROS2): its basic port is known, the list complete.
class Fib : public BT::RosActionNode<Fibonacci>
{
public:
  static BT::PortsList providedPorts()
  {
    return providedBasicPorts({ BT::InputPort<unsigned>("order") });
  }
};

// A base of a BehaviorTree.ROS2 fork: an action, its basic ports are the fork's.
class PubTwist : public BT::RosTopicPubStatefulActionNode<Twist>
{
public:
  static BT::PortsList providedPorts() { return providedBasicPorts({ BT::InputPort<double>("v") }); }
};

BT_REGISTER_NODES(factory)
{
  factory.registerNodeType<PubTwist>("PubTwist");
  factory.registerNodeType<Grip>("Grip");
  factory.registerNodeType<Fib>("Fib");
}
