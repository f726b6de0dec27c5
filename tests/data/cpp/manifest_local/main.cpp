#include <behaviortree_cpp/bt_factory.h>
using namespace BT;

class Think : public SyncActionNode
{
public:
  Think(const std::string& name, const NodeConfig& config, int) : SyncActionNode(name, config) {}
};

NodeStatus Say(TreeNode&) { return NodeStatus::SUCCESS; }

int main()
{
  BehaviorTreeFactory factory;
  // Ports built in a local variable, then passed to CreateManifest.
  PortsList think_ports = { BT::OutputPort<std::string>("text") };
  think_ports.insert(BT::InputPort<int>("depth", 2, "how deep"));
  factory.registerBuilder(CreateManifest<Think>("Think", think_ports), CreateBuilder<Think>());
  // ... and to a simple action.
  PortsList say_ports = { InputPort<std::string>("message") };
  factory.registerSimpleAction("Say", Say, say_ports);
}
