#pragma once

#include <ros/ros.h>

#include <exception>

namespace sift_hull {

/// main() of a node: init, the node on the global and private handles, spin. An error while
/// setting it up is logged as fatal, with exit code 1.
template <typename Node>
int runNode(int argc, char** argv, const char* name) {
  ros::init(argc, argv, name);
  // Outlive the node: ROS shuts down with the last NodeHandle, and the error below would be lost.
  ros::NodeHandle nh, private_nh("~");
  try {
    Node node(nh, private_nh);
    ros::spin();
  } catch (const std::exception& e) {
    ROS_FATAL("%s: %s", name, e.what());
    return 1;
  }
  return 0;
}

}  // namespace sift_hull
