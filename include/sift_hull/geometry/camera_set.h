#pragma once

#include <Eigen/Core>
#include <vector>

#include "sift_hull/geometry/camera.h"

namespace sift_hull {

/// Where the views' optical axes come closest to meeting (least squares over the axes).
struct CommonPoint {
  Eigen::Vector3d point_W = Eigen::Vector3d::Zero();
  /// Largest distance of the point from an optical axis, in world units (metres for scenes).
  double max_axis_distance_m = 0.0;
  bool in_front_of_all = false;  ///< the point has positive depth in every view
  bool well_defined = false;     ///< the axes are not all parallel (needs two views or more)
  int first_behind = -1;         ///< index of the first camera the point is behind, -1 if none
};

/// The point nearest to all the cameras' optical axes (least squares), with how far it is from the
/// farthest axis and whether it lies in front of every camera; not well defined when the axes are
/// all parallel or there are fewer than two cameras.
CommonPoint opticalAxesMeetingPoint(const std::vector<PinholeCamera>& cameras);

}  // namespace sift_hull
