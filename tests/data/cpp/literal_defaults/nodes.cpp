#include <behaviortree_cpp/bt_factory.h>
using namespace std::string_literals;

// Defaults written as C++ literals, shown as BehaviorTree.CPP's toStr writes them.
class Tune : public BT::SyncActionNode
{
public:
  static BT::PortsList providedPorts()
  {
    return {
      BT::InputPort<float>("gain", 0.7f, ""),
      BT::InputPort<int>("steps", 1e3, ""),
      BT::InputPort<unsigned>("count", 10u, ""),
      BT::InputPort<unsigned>("wrapped", -1, ""),
      BT::InputPort<double>("scale", 2, ""),
      BT::InputPort<bool>("on", true, ""),
      BT::InputPort<bool>("flag", 1, ""),
      BT::InputPort<std::string>("frame", std::string("map"), ""),
      BT::InputPort<std::string>("link", "base"s, ""),
      BT::InputPort("any", 5, ""),
      BT::InputPort<double>("text", "0.5", ""),
      BT::InputPort<Mode>("mode", 3, ""),
    };
  }
};

BT_REGISTER_NODES(factory) { factory.registerNodeType<Tune>("Tune"); }
