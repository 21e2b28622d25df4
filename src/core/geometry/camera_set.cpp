#include "sift_hull/geometry/camera_set.h"

#include <Eigen/Dense>
#include <algorithm>
#include <cmath>
#include <iomanip>
#include <sstream>
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

namespace {

/// The median of `values` (the upper one of an even count).
double median(std::vector<double> values) {
  std::nth_element(values.begin(), values.begin() + values.size() / 2, values.end());
  return values[values.size() / 2];
}

}  // namespace

void requireNoStrayCamera(const std::vector<PinholeCamera>& cameras,
                          const std::vector<std::string>& names) {
  if (cameras.size() < 3) return;
  Eigen::Vector3d centre;
  for (int axis = 0; axis < 3; ++axis) {
    std::vector<double> coordinates;
    for (const PinholeCamera& camera : cameras) coordinates.push_back(camera.centre()(axis));
    centre(axis) = median(coordinates);
  }
  std::vector<double> distances;
  for (const PinholeCamera& camera : cameras) {
    distances.push_back((camera.centre() - centre).stableNorm());  // no overflow near 1e308
  }
  const double typical = median(distances);
  if (!(typical > 0.0) || !std::isfinite(typical)) return;
  for (size_t i = 0; i < cameras.size(); ++i) {
    if (distances[i] <= kMaxCameraSpread * typical) continue;
    std::ostringstream message;
    message << std::setprecision(3) << "view '"
            << (names.size() == cameras.size() ? names[i] : std::to_string(i))
            << "': its camera lies " << distances[i]
            << " from the cameras' median centre, more than " << kMaxCameraSpread
            << " times their median distance from it (" << typical << "): check its translation";
    throw std::invalid_argument(message.str());
  }
}

}  // namespace sift_hull
