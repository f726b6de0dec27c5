#include <behaviortree_cpp/bt_factory.h>
#include <nav2_msgs/action/spin.hpp>
#include "fleet/types.hpp"

namespace fleet
{
// Writes every entry, each with a type spelled through an alias.
class Plan : public BT::SyncActionNode
{
public:
  typedef int Level;
  using Count = std::uint16_t;
  Plan(const std::string & n, const BT::NodeConfig & c) : BT::SyncActionNode(n, c) {}
  static BT::PortsList providedPorts()
  {
    return {
      BT::OutputPort<TaskPtr>("task"),
      BT::OutputPort<PoseStamped>("goal"),
      BT::OutputPort<fleet::MissionPtr>("mission"),
      BT::OutputPort<List<Task>>("tasks"),
      BT::OutputPort<Twist>("cmd"),
      BT::OutputPort<Level>("level"),
      BT::OutputPort<Plan::Count>("count"),
      BT::OutputPort<Task>("job"),
    };
  }
  BT::NodeStatus tick() override { return BT::NodeStatus::SUCCESS; }
};

// Reads them, spelled without the aliases (or, for the last two, as other types).
class Run : public BT::SyncActionNode
{
public:
  Run(const std::string & n, const BT::NodeConfig & c) : BT::SyncActionNode(n, c) {}
  static BT::PortsList providedPorts();
  BT::NodeStatus tick() override { return BT::NodeStatus::SUCCESS; }
};

// Types bt-lsp cannot resolve: a member of a generated action type, a template
// parameter's member, an alias from a header outside the project.
template <class ActionT>
class RosStep : public BT::SyncActionNode
{
public:
  using Goal = typename ActionT::Goal;
  RosStep(const std::string & n, const BT::NodeConfig & c) : BT::SyncActionNode(n, c) {}
};

class Spin : public RosStep<nav2_msgs::action::Spin>
{
  using Action = nav2_msgs::action::Spin;
  using ActionResult = Action::Result;

public:
  Spin(const std::string & n, const BT::NodeConfig & c) : RosStep(n, c) {}
  static BT::PortsList providedPorts()
  {
    return {
      BT::OutputPort<ActionResult::_error_code_type>("error_code"),
      BT::InputPort<Goal>("goal"),
      BT::InputPort<ExternalPtr>("task"),
    };
  }
  BT::NodeStatus tick() override { return BT::NodeStatus::SUCCESS; }
};
}  // namespace fleet

BT::PortsList fleet::Run::providedPorts()
{
  return {
    BT::InputPort<std::shared_ptr<Task>>("task"),
    BT::InputPort<geometry_msgs::msg::PoseStamped>("goal"),
    BT::InputPort<std::shared_ptr<fleet::Mission>>("mission"),
    BT::InputPort<std::vector<fleet::Task>>("tasks"),
    BT::InputPort<geometry_msgs::msg::Twist>("cmd"),
    BT::InputPort<int>("level"),
    BT::InputPort<uint16_t>("count"),
    BT::InputPort<Mission>("job"),
    BT::InputPort<double>("depth"),
  };
}

BT_REGISTER_NODES(factory)
{
  factory.registerNodeType<fleet::Plan>("Plan");
  factory.registerNodeType<fleet::Run>("Run");
  factory.registerNodeType<fleet::Spin>("Spin");
}
