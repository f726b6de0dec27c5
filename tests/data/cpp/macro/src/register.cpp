#include "demo/nodes.hpp"

#define REGISTER_NODE(Name)                                                  \
  factory.registerBuilder<Name>(#Name, [](const std::string& n, const BT::NodeConfig& c) { \
    return std::make_unique<Name>(n, c);                                      \
  });

// Three arguments: the class, the ID and a constructor argument.
#define REGISTER_WITH(Type, Id, Arg) factory.registerNodeType<Type>(Id, Arg);

BT_REGISTER_NODES(factory)
{
  REGISTER_NODE(Dock)
  REGISTER_NODE(Undock)
  REGISTER_WITH(Charge, "ChargeSlowly", 2)
}
