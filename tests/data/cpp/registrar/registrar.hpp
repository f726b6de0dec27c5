#pragma once
#include <behaviortree_cpp/bt_factory.h>
#include <functional>
#include <vector>

using Registration = std::function<void(BT::BehaviorTreeFactory&)>;
std::vector<Registration>& registry();

// A static object per node queues its registration; main() runs the queue.
template <class T>
struct NodeRegistrar
{
  explicit NodeRegistrar(const std::string& id)
  {
    registry().push_back([id](BT::BehaviorTreeFactory& f) { f.registerNodeType<T>(id); });
  }
};

#define REGISTER_BT_NODE(Class) static NodeRegistrar<Class> registrar_##Class(#Class);
