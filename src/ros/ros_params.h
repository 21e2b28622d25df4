#pragma once

// One reader per config struct; every fallback is the struct's own default.

#include <ros/node_handle.h>

#include "sift_hull/hull_stream.h"

namespace sift_hull {
namespace ros_params {

/// ~depth, ~carve_outside_image, ~slack_px, ~threads.
HullConfig readHullConfig(const ros::NodeHandle& private_nh);

/// The hull config, ~box ([xmin, ymin, zmin, xmax, ymax, zmax] in the world frame, metres; empty
/// or absent: automatic) and ~skip_views (frame ids of silhouettes to leave out). Throws
/// std::invalid_argument for a box that is not six numbers with max > min.
HullStreamConfig readHullStreamConfig(const ros::NodeHandle& private_nh);

}  // namespace ros_params
}  // namespace sift_hull
