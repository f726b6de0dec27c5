#include "pkg/service_base.hpp"

namespace pkg
{
class SetMode : public ServiceNode<mode_msgs::srv::SetMode>
{
public:
  static BT::PortsList providedPorts()
  {
    return providedBasicPorts({ BT::InputPort<std::string>("mode", "auto", "") });
  }
};

class Reset : public ServiceNode<std_srvs::srv::Empty>
{
};
}  // namespace pkg

BT_REGISTER_NODES(factory)
{
  factory.registerNodeType<pkg::SetMode>("SetMode");
  factory.registerNodeType<pkg::Reset>("Reset");
  factory.registerNodeType<pkg::GetValue<int>>("GetInt");
}
