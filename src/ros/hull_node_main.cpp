#include <ros/ros.h>

#include "hull_node.h"

int main(int argc, char** argv) {
  ros::init(argc, argv, "hull_node");
  try {
    sift_hull::HullNode node(ros::NodeHandle(), ros::NodeHandle("~"));
    ros::spin();
  } catch (const std::exception& e) {
    ROS_FATAL("hull_node: %s", e.what());
    return 1;
  }
  return 0;
}
