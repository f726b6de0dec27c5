#include <behaviortree_cpp/bt_factory.h>

int main()
{
  BT::BehaviorTreeFactory factory;
  factory.registerFromPlugin("libtakeoff.so");
}
