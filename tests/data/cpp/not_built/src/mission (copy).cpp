// An old program that no target builds: its own Takeoff, under the same ID.
#include <behaviortree_cpp/bt_factory.h>

class Takeoff : public BT::SyncActionNode
{
public:
  static BT::PortsList providedPorts()
  {
    return { BT::InputPort<std::string>("takeoff_target") };
  }
};

class MoveUp : public BT::SyncActionNode
{
public:
  static BT::PortsList providedPorts() { return { BT::InputPort<double>("distance") }; }
};

int main()
{
  BT::BehaviorTreeFactory factory;
  factory.registerNodeType<Takeoff>("Takeoff");
  factory.registerNodeType<MoveUp>("MoveUp");
}
