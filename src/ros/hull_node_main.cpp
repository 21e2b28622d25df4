#include <ros/ros.h>

#include "hull_node.h"

int main(int argc, char** argv) {
  ros::init(argc, argv, "hull_node");
  // Outlive the node: ROS shuts down with the last NodeHandle, and the error below would be lost.
  ros::NodeHandle nh, private_nh("~");
  try {
    sift_hull::HullNode node(nh, private_nh);
    ros::spin();
  } catch (const std::exception& e) {
    ROS_FATAL("hull_node: %s", e.what());
    return 1;
  }
  return 0;
}
