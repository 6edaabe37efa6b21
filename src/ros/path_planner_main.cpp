// path_planner: see path_planner_node.h.

#include <ros/ros.h>

#include "path_planner_node.h"

int main(int argc, char** argv) {
  ros::init(argc, argv, "path_planner");
  ros::NodeHandle node;
  ros::NodeHandle private_node("~");
  maximal_workspace::PathPlannerNode planner(node, private_node);
  ros::AsyncSpinner spinner(2);
  spinner.start();
  ros::waitForShutdown();
  return 0;
}
