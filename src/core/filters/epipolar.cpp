#include "sift_hull/filters/epipolar.h"

#include <stdexcept>

#include "sift_hull/geometry/camera.h"

namespace sift_hull {
namespace {

Eigen::Vector2d position(const cv::KeyPoint& keypoint) { return {keypoint.pt.x, keypoint.pt.y}; }

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
  return keepNearEpipolarLines(input, *input.F_right_left, config.max_epipolar_px);
}

}  // namespace sift_hull
