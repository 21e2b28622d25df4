#include "sift_hull/geometry/camera_set.h"

#include <Eigen/Dense>
#include <algorithm>
#include <stdexcept>

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

CameraOrientation orientCameras(std::vector<PinholeCamera>* cameras,
                                const std::vector<std::string>& names) {
  CameraOrientation result;
  const CommonPoint scene = opticalAxesMeetingPoint(*cameras);
  if (!scene.well_defined) return result;
  result.by_scene_point = true;
  std::vector<size_t> proper, improper;
  for (size_t i = 0; i < cameras->size(); ++i) {
    PinholeCamera& camera = (*cameras)[i];
    if (camera.depth(scene.point_W) < 0.0) {
      camera = camera.negated();
      result.negated.push_back(i);
    }
    (camera.improper() ? improper : proper).push_back(i);
  }
  result.mirrored_world = proper.empty();
  if (proper.empty() || improper.empty()) return result;
  const bool few_improper = improper.size() <= proper.size();
  const std::vector<size_t>& odd = few_improper ? improper : proper;
  std::string list;
  for (size_t i : odd) {
    if (!list.empty()) list += ", ";
    list += names.size() == cameras->size() ? "'" + names[i] + "'" : "view " + std::to_string(i);
  }
  throw std::invalid_argument(
      "the cameras cannot be oriented consistently: " + list +
      " see the scene (where the optical axes meet) behind them unless their world frame is " +
      (few_improper ? "mirrored" : "right-handed") + " while the other cameras' is " +
      (few_improper ? "right-handed" : "mirrored") + "; check their projection matrices");
}

double camerasMutualDistance(const std::vector<PinholeCamera>& cameras) {
  double distance = 0.0;
  for (size_t i = 0; i < cameras.size(); ++i) {
    for (size_t j = i + 1; j < cameras.size(); ++j) {
      distance = std::max(distance, (cameras[i].centre() - cameras[j].centre()).norm());
    }
  }
  return distance;
}

}  // namespace sift_hull
