#pragma once
#include <behaviortree_cpp/bt_factory.h>

class MoveBase : public BT::StatefulActionNode
{
public:
  static BT::PortsList providedPorts()
  {
    return BT::PortsList({ BT::InputPort<double>("speed", 1.0, "m/s"),
                           BT::InputPort<std::string>("frame", "map", "") });
  }
};

class Task : public MoveBase
{
public:
  static BT::PortsList providedPorts();
};

class Alias : public MoveBase
{
public:
  using MoveBase::providedPorts;
};

class Inherits : public MoveBase
{
};
