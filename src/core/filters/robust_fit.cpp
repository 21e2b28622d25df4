#include "sift_hull/filters/robust_fit.h"

#include <opencv2/calib3d.hpp>
#include <opencv2/core/eigen.hpp>
#include <stdexcept>
#include <vector>

#include "sift_hull/filters/epipolar.h"

namespace sift_hull {
namespace {

void requireFit(bool condition, const std::string& message) {
  if (!condition) throw std::invalid_argument("filter config: " + message);
}

/// F estimated robustly by cv::findFundamentalMat with `method`; nothing kept when it fails.
FilterResult fitFundamentalMatrix(const PutativeMatches& input, int method,
                                  const RobustFitConfig& config) {
  std::vector<cv::Point2f> left, right;
  for (size_t m = 0; m < input.matches.size(); ++m) {
    if (!input.hasFinitePositions(m)) continue;
    left.push_back(input.left(m).pt);
    right.push_back(input.right(m).pt);
  }
  if (left.size() < 8) return FilterResult::keepingNone(input.matches.size());
  const cv::Mat F = cv::findFundamentalMat(left, right, method, config.max_epipolar_px,
                                           config.confidence, config.max_iterations);
  if (F.rows < 3 || F.cols != 3) return FilterResult::keepingNone(input.matches.size());
  Eigen::Matrix3d F_right_left;
  cv::cv2eigen(F.rowRange(0, 3), F_right_left);
  return keepNearEpipolarLines(input, F_right_left, config.max_epipolar_px);
}

}  // namespace

void validate(const RobustFitConfig& config, const std::string& name) {
  requireFit(config.max_epipolar_px > 0.0, name + ".max_epipolar_px must be > 0");
  requireFit(config.confidence > 0.0 && config.confidence < 1.0,
             name + ".confidence must be in (0, 1)");
  requireFit(config.max_iterations >= 1, name + ".max_iterations must be >= 1");
}

FilterResult filterRansac(const PutativeMatches& input, const RobustFitConfig& config) {
  return fitFundamentalMatrix(input, cv::FM_RANSAC, config);
}

FilterResult filterMagsac(const PutativeMatches& input, const RobustFitConfig& config) {
  return fitFundamentalMatrix(input, cv::USAC_MAGSAC, config);
}

}  // namespace sift_hull
