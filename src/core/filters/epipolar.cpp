#include "sift_hull/filters/epipolar.h"

#include <Eigen/LU>
#include <algorithm>
#include <cmath>
#include <optional>
#include <stdexcept>

#include "sift_hull/geometry/camera.h"

namespace sift_hull {
namespace {

Eigen::Vector2d position(const cv::KeyPoint& keypoint) { return {keypoint.pt.x, keypoint.pt.y}; }

/// Distance in raw pixels of a point to an epipolar curve, from its distance in ideal pixels to the
/// epipolar line (unit normal `normal`): near the point, the lens maps ideal pixels to raw ones by
/// its Jacobian J, which takes the line to one at distance d / |J^-T n| (to first order).
double rawDistance(const PinholeCamera& camera, const Eigen::Vector2d& ideal_px,
                   const Eigen::Vector3d& line, double ideal_distance_px) {
  const double norm = line.head<2>().norm();
  if (!(norm > 0.0) || !std::isfinite(ideal_distance_px)) return ideal_distance_px;
  const Eigen::Matrix3d& K = camera.K();
  const Eigen::Vector2d normalised = (K.inverse() * ideal_px.homogeneous()).hnormalized();
  const Eigen::Matrix2d K2 = K.topLeftCorner<2, 2>();
  const Eigen::Matrix2d J = K2 * distortionJacobian(camera.distortion(), normalised) * K2.inverse();
  return ideal_distance_px / (J.inverse().transpose() * (line.head<2>() / norm)).norm();
}

/// keepNearEpipolarLines for cameras with lens distortion: the points undistorted, the distances
/// measured in raw pixels, as max_px is.
FilterResult keepNearDistortedEpipolarLines(const PutativeMatches& input, const Eigen::Matrix3d& F,
                                            const PinholeCamera& left, const PinholeCamera& right,
                                            double max_px) {
  FilterResult result = FilterResult::keepingNone(input.matches.size());
  for (size_t m = 0; m < input.matches.size(); ++m) {
    if (!input.hasFinitePositions(m)) continue;
    const std::optional<Eigen::Vector2d> a = left.undistortPixel(position(input.left(m)));
    const std::optional<Eigen::Vector2d> b = right.undistortPixel(position(input.right(m)));
    if (!a || !b) continue;  // beyond where the lens model holds: not a point it imaged
    const EpipolarDistances ideal = epipolarDistances(F, *a, *b);
    const double distance =
        std::max(rawDistance(left, *a, F.transpose() * b->homogeneous(), ideal.in_a_px),
                 rawDistance(right, *b, F * a->homogeneous(), ideal.in_b_px));
    result.score[m] = distance;
    result.keep[m] = distance <= max_px;
  }
  return result;
}

}  // namespace

FilterResult keepNearEpipolarLines(const PutativeMatches& input, const Eigen::Matrix3d& F,
                                   double max_px) {
  FilterResult result = FilterResult::keepingNone(input.matches.size());
  for (size_t m = 0; m < input.matches.size(); ++m) {
    if (!input.hasFinitePositions(m)) continue;
    const double distance =
        epipolarDistances(F, position(input.left(m)), position(input.right(m))).max();
    result.score[m] = distance;
    result.keep[m] = distance <= max_px;
  }
  return result;
}

FilterResult filterEpipolar(const PutativeMatches& input, const EpipolarConfig& config) {
  if (!input.F_right_left) {
    throw std::invalid_argument(
        "the epipolar filter needs calibration (a fundamental matrix for the pair)");
  }
  if (!input.cameras || (!input.cameras->first.distorted() && !input.cameras->second.distorted())) {
    return keepNearEpipolarLines(input, *input.F_right_left, config.max_distance_px);
  }
  return keepNearDistortedEpipolarLines(input, *input.F_right_left, input.cameras->first,
                                        input.cameras->second, config.max_distance_px);
}

}  // namespace sift_hull
