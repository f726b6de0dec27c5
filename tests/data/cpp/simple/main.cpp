#include <behaviortree_cpp/bt_factory.h>

BT::NodeStatus CheckBattery() { return BT::NodeStatus::SUCCESS; }

void RegisterSimple(BT::BehaviorTreeFactory& factory)
{
  BT::PortsList say_ports = { BT::InputPort<std::string>("text") };
  factory.registerSimpleAction("Say", [](BT::TreeNode&) { return BT::NodeStatus::SUCCESS; },
                               { BT::InputPort<std::string>("text"), BT::OutputPort<int>("len") });
  factory.registerSimpleCondition("CheckBattery", std::bind(CheckBattery));
  factory.registerSimpleDecorator("Twice", [](BT::NodeStatus s, BT::TreeNode&) { return s; });
}
