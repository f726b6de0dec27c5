#include <behaviortree_cpp/bt_factory.h>

class OtherNode : public BT::SyncActionNode
{
public:
  static BT::PortsList providedPorts() { return {}; }
};

BT_REGISTER_NODES(factory) { factory.registerNodeType<OtherNode>("OtherNode"); }
