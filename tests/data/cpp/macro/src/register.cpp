#include "demo/nodes.hpp"

#define REGISTER_NODE(Name)                                                  \
  factory.registerBuilder<Name>(#Name, [](const std::string& n, const BT::NodeConfig& c) { \
    return std::make_unique<Name>(n, c);                                      \
  });

BT_REGISTER_NODES(factory)
{
  REGISTER_NODE(Dock)
  REGISTER_NODE(Undock)
}
