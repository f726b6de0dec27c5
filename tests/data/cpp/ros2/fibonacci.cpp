#include <behaviortree_ros2/bt_action_node.hpp>
#include <behaviortree_ros2/bt_topic_sub_node.hpp>
#include <behaviortree_ros2/plugins.hpp>

using Fibonacci = example_interfaces::action::Fibonacci;

class FibonacciAction : public BT::RosActionNode<Fibonacci>
{
public:
  static BT::PortsList providedPorts()
  {
    return providedBasicPorts({ BT::InputPort<unsigned>("order", "how many numbers") });
  }
};

class ReceiveString : public BT::RosTopicSubNode<std_msgs::msg::String>
{
public:
  static BT::PortsList providedPorts() { return providedBasicPorts({}); }
};

CreateRosNodePlugin(FibonacciAction, "Fibonacci");
CreateRosNodePlugin(ReceiveString, "ReceiveString");
