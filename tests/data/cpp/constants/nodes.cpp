#include <behaviortree_cpp/bt_factory.h>

#define TOPIC_PORT "topic"
constexpr const char* kRobotId = "robot_id";

class Follow : public BT::SyncActionNode
{
public:
  static const std::string TARGET;
  static constexpr const char* SPEED = "follow_speed";
  static BT::PortsList providedPorts()
  {
    return { BT::InputPort<std::string>(TARGET), BT::InputPort<double>(SPEED),
             BT::InputPort<std::string>(TOPIC_PORT), BT::InputPort<int>(kRobotId) };
  }
};
const std::string Follow::TARGET = "target";

class Flee : public BT::SyncActionNode
{
public:
  static constexpr const char* SPEED = "flee_speed";
  static BT::PortsList providedPorts() { return { BT::InputPort<double>(SPEED),
                                                  BT::InputPort<double>(Follow::SPEED) }; }
};

static const std::string kFleeId = "Flee";

BT_REGISTER_NODES(factory)
{
  factory.registerNodeType<Follow>("Follow");
  factory.registerNodeType<Flee>(kFleeId);
}
