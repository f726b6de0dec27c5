#include <behaviortree_cpp/bt_factory.h>

class Approach : public BT::SyncActionNode
{
public:
  static BT::PortsList providedPorts() { return { BT::InputPort<double>("speed") }; }
};

void Register(BT::BehaviorTreeFactory& factory)
{
  factory.registerBuilder(BT::CreateManifest<Approach>("Approach"), BT::CreateBuilder<Approach>());
  factory.registerBuilder(
      BT::CreateManifest<Approach>("ApproachSlowly", { BT::InputPort<double>("limit", 0.1, "max") }),
      BT::CreateBuilder<Approach>());
}
