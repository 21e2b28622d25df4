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
};

CommonPoint opticalAxesMeetingPoint(const std::vector<PinholeCamera>& cameras);

}  // namespace sift_hull
