// Type names of the fleet package; no node is declared here, so the catalog reads this
// file only because the nodes name what it defines.
#pragma once
#include <memory>
#include <vector>
#include <geometry_msgs/msg/pose_stamped.hpp>
#include <geometry_msgs/msg/twist.hpp>

namespace fleet
{
struct Task
{
  int id;
};
struct Mission
{
  std::vector<Task> tasks;
};
struct Goal
{
  double x;
};

using TaskPtr = std::shared_ptr<Task>;
typedef std::shared_ptr<Mission> MissionPtr, *MissionPtrPtr;
using PoseStamped = geometry_msgs::msg::PoseStamped;
using geometry_msgs::msg::Twist;
template <class T>
using List = std::vector<T>;
using namespace std;  // not an alias: `string` below is still std::string
}  // namespace fleet
