#include <behaviortree_cpp/bt_factory.h>

namespace demo
{
// Every argument form of the port functions.
class SaySomething : public BT::SyncActionNode
{
public:
  SaySomething(const std::string& name, const BT::NodeConfig& config, int extra)
    : BT::SyncActionNode(name, config) {}

  static BT::PortsList providedPorts()
  {
    return { BT::InputPort<std::string>("message"),
             BT::InputPort<int>("times", "how often"),
             BT::InputPort<double>("pause", 0.5, "seconds between two"),
             BT::InputPort<bool>("loud", false, "shout"),
             BT::InputPort<int>("offset", -3, "signed default"),
             BT::InputPort("anything", "no type given"),
             BT::OutputPort<std::string>("said"),
             BT::OutputPort<int>("count", "how many were said"),
             BT::OutputPort<int>("last", "{last_count}", "default key"),
             BT::BidirectionalPort<std::vector<int>>("queue", "shared queue") };
  }
  BT::NodeStatus tick() override { return BT::NodeStatus::SUCCESS; }
};

class IsReady : public BT::ConditionNode
{
public:
  using BT::ConditionNode::ConditionNode;
  static BT::PortsList providedPorts() { return {}; }
  BT::NodeStatus tick() override { return BT::NodeStatus::SUCCESS; }
};

class Gate : public BT::DecoratorNode
{
public:
  static BT::PortsList providedPorts() { return { BT::InputPort<unsigned int>("limit", 3, "") }; }
};

class Pick : public BT::ControlNode
{
};

class NeverRegistered : public BT::SyncActionNode
{
public:
  static BT::PortsList providedPorts() { return { BT::InputPort<int>("x") }; }
};
}  // namespace demo

int main()
{
  BT::BehaviorTreeFactory factory;
  factory.registerNodeType<demo::SaySomething>("SaySomething", 42);
  factory.registerNodeType<demo::IsReady>("IsReady");
  factory.registerNodeType<demo::Gate>("Gate");
  auto f = &factory;
  f->registerNodeType<demo::Pick>("Pick");
  return 0;
}
