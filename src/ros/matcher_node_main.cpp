#include <ros/ros.h>

#include "matcher_node.h"

int main(int argc, char** argv) {
  ros::init(argc, argv, "matcher_node");
  try {
    sift_hull::MatcherNode node(ros::NodeHandle(), ros::NodeHandle("~"));
    ros::spin();
  } catch (const std::exception& e) {
    ROS_FATAL("matcher_node: %s", e.what());
    return 1;
  }
  return 0;
}
