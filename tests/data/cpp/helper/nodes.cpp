#include <behaviortree_cpp/bt_factory.h>

class Dock : public BT::SyncActionNode
{
public:
  static BT::PortsList providedPorts() { return { BT::InputPort<std::string>("station") }; }
};

class Undock : public BT::SyncActionNode
{
public:
  static BT::PortsList providedPorts() { return {}; }
};

// The project's own helpers: the class is a template parameter, the ID a parameter.
template <class T>
void reg(BT::BehaviorTreeFactory& f, const std::string& n)
{
  f.registerNodeType<T>(n);
}

template <typename NodeType>
void registerCustomNode(BT::BehaviorTreeFactory& factory, const std::string& registration_id,
                        int& handle)
{
  BT::NodeBuilder builder = [&handle](const std::string& name, const BT::NodeConfig& config) {
    return std::make_unique<NodeType>(handle, name, config);
  };
  factory.registerBuilder<NodeType>(registration_id, builder);
}

// A fixed class, the ID from the caller.
void registerUndock(BT::BehaviorTreeFactory& factory, const char* id)
{
  factory.registerNodeType<Undock>(id);
}

int main()
{
  BT::BehaviorTreeFactory factory;
  int handle = 0;
  reg<Dock>(factory, "Dock");
  registerCustomNode<Dock>(
      factory, "DockToo", handle);
  registerUndock(factory, "Undock");
}
