#include "registrar.hpp"

class Beep : public BT::SyncActionNode
{
public:
  static BT::PortsList providedPorts() { return { BT::InputPort<int>("times", 2, "") }; }
};

class Blink : public BT::ConditionNode
{
public:
  static BT::PortsList providedPorts() { return {}; }
};

REGISTER_BT_NODE(Beep)
static NodeRegistrar<Blink> blink_registrar("BlinkTwice");

// A macro of the same shape around a class template that registers nothing.
template <class T>
struct Counter
{
  explicit Counter(const std::string& label) {}
};
#define COUNT(Class) static Counter<Class> counter_##Class(#Class);
COUNT(Beep)
