#include "sift_hull/geometry/camera_set.h"

#include <Eigen/Dense>
#include <algorithm>

namespace sift_hull {

CommonPoint opticalAxesMeetingPoint(const std::vector<PinholeCamera>& cameras) {
  // Minimises sum_i |(I - a_i a_i^T)(X - c_i)|^2 over X, a_i the unit axis and c_i the centre.
  Eigen::Matrix3d A = Eigen::Matrix3d::Zero();
  Eigen::Vector3d b = Eigen::Vector3d::Zero();
  for (const PinholeCamera& camera : cameras) {
    const Eigen::Vector3d axis = camera.opticalAxis();
    const Eigen::Matrix3d projector = Eigen::Matrix3d::Identity() - axis * axis.transpose();
    A += projector;
    b += projector * camera.centre();
  }
  CommonPoint result;
  const Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> eigen(A);
  result.well_defined =
      cameras.size() >= 2 && eigen.eigenvalues().minCoeff() > 1e-6 * cameras.size();
  if (!result.well_defined) return result;
  result.point_W = A.ldlt().solve(b);
  result.in_front_of_all = true;
  for (const PinholeCamera& camera : cameras) {
    const Eigen::Vector3d axis = camera.opticalAxis();
    const Eigen::Vector3d offset = result.point_W - camera.centre();
    const double distance = (offset - axis * axis.dot(offset)).norm();
    result.max_axis_distance_m = std::max(result.max_axis_distance_m, distance);
    if (!(camera.depth(result.point_W) > 0.0) && result.in_front_of_all) {
      result.in_front_of_all = false;
      result.first_behind = static_cast<int>(&camera - cameras.data());
    }
  }
  return result;
}

}  // namespace sift_hull
