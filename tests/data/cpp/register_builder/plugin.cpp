#include "behaviortree_cpp/bt_factory.h"

namespace nav_like
{
class ClearMap : public BT::SyncActionNode
{
public:
  ClearMap(const std::string& xml_tag_name, const BT::NodeConfiguration& conf);
  static BT::PortsList providedPorts()
  {
    return {
      BT::InputPort<std::string>("service_name", "/clear", "Service to call"),
      BT::InputPort<std::chrono::milliseconds>("server_timeout"),
    };
  }
};
}  // namespace nav_like

BT_REGISTER_NODES(factory)
{
  BT::NodeBuilder builder = [](const std::string& name, const BT::NodeConfiguration& config)
  {
    return std::make_unique<nav_like::ClearMap>(name, config);
  };
  factory.registerBuilder<nav_like::ClearMap>("ClearEntireCostmap", builder);
}
