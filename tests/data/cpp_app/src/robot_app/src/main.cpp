#include <behaviortree_cpp/bt_factory.h>
#include <robot_lib/charge.hpp>

class Dock : public BT::StatefulActionNode
{
public:
  Dock(const std::string& name, const BT::NodeConfig& config) : BT::StatefulActionNode(name, config) {}
  static BT::PortsList providedPorts()
  {
    return { BT::InputPort<std::string>("station", "Docking station"),
             BT::InputPort<double>("timeout", 30.0, "Seconds to wait") };
  }
  BT::NodeStatus onStart() override { return BT::NodeStatus::RUNNING; }
  BT::NodeStatus onRunning() override { return BT::NodeStatus::SUCCESS; }
  void onHalted() override {}
};

int main()
{
  BT::BehaviorTreeFactory factory;
  factory.registerNodeType<Dock>("Dock");
  robot_lib::registerNodes(factory);
  auto tree = factory.createTreeFromFile("trees/app.xml");
  tree.tickWhileRunning();
  return 0;
}
