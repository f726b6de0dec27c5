#pragma once
#include <behaviortree_cpp/bt_factory.h>

// The class is named from two parameters; continuation lines between the tokens.
#define REGISTER_NODES(node_namespace, class_name)                                    \
  BT_REGISTER_NODES(factory)                                                          \
  {                                                                                   \
    factory.registerBuilder<node_namespace::class_name>(                              \
      #class_name, builder_of<node_namespace::class_name>());                         \
  }
