#include "sift_hull/filters/robust_fit.h"

#include <opencv2/calib3d.hpp>
#include <opencv2/core/eigen.hpp>
#include <stdexcept>
#include <vector>

#include "sift_hull/filters/epipolar.h"

namespace sift_hull {
namespace {

/// OpenCV's USAC_MAGSAC flag spelled out (its sampler, score and local optimisation), so that the
/// random state can be set.
cv::UsacParams magsacParams(double threshold_px, const RobustFitConfig& config, bool homography) {
  cv::UsacParams params;
  params.threshold = threshold_px;
  params.confidence = config.confidence;
  params.maxIterations = config.max_iterations;
  params.sampler = cv::SAMPLING_UNIFORM;
  params.score = cv::SCORE_METHOD_MAGSAC;
  params.loMethod = cv::LOCAL_OPTIM_SIGMA;
  params.loSampleSize = homography ? 75 : 50;
  params.loIterations = homography ? 15 : 10;
  params.isParallel = false;
  params.randomGeneratorState = config.seed;
  return params;
}

/// Plain RANSAC (uniform samples, inlier counting, no local optimisation) through USAC, so that
/// the random state can be set.
cv::Mat ransacFundamentalMatrix(const std::vector<cv::Point2f>& left,
                                const std::vector<cv::Point2f>& right,
                                const RobustFitConfig& config) {
  cv::UsacParams params;
  params.threshold = config.max_epipolar_px;
  params.confidence = config.confidence;
  params.maxIterations = config.max_iterations;
  params.sampler = cv::SAMPLING_UNIFORM;
  params.score = cv::SCORE_METHOD_RANSAC;
  params.loMethod = cv::LOCAL_OPTIM_NULL;
  params.isParallel = false;
  params.randomGeneratorState = config.seed;
  cv::Mat mask;
  try {
    return cv::findFundamentalMat(left, right, mask, params);
  } catch (const cv::Exception&) {
    return {};
  }
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
  const cv::Mat F = method == cv::USAC_MAGSAC ? magsacFundamentalMatrix(left, right, config)
                                              : ransacFundamentalMatrix(left, right, config);
  if (F.rows < 3 || F.cols != 3) return FilterResult::keepingNone(input.matches.size());
  Eigen::Matrix3d F_right_left;
  cv::cv2eigen(F.rowRange(0, 3), F_right_left);
  return keepNearEpipolarLines(input, F_right_left, config.max_epipolar_px);
}

}  // namespace

cv::Mat magsacFundamentalMatrix(const std::vector<cv::Point2f>& left,
                                const std::vector<cv::Point2f>& right,
                                const RobustFitConfig& config) {
  if (left.size() < 8 || left.size() != right.size()) return {};
  cv::Mat mask;
  try {
    return cv::findFundamentalMat(left, right, mask,
                                  magsacParams(config.max_epipolar_px, config, false));
  } catch (const cv::Exception&) {
    return {};  // degenerate samples only
  }
}

cv::Mat magsacHomography(const std::vector<cv::Point2f>& left,
                         const std::vector<cv::Point2f>& right, double max_transfer_px,
                         const RobustFitConfig& config) {
  if (left.size() < 4 || left.size() != right.size()) return {};
  cv::Mat mask;
  try {
    return cv::findHomography(left, right, mask, magsacParams(max_transfer_px, config, true));
  } catch (const cv::Exception&) {
    return {};
  }
}

FilterResult filterRansac(const PutativeMatches& input, const RobustFitConfig& config) {
  return fitFundamentalMatrix(input, cv::FM_RANSAC, config);
}

FilterResult filterMagsac(const PutativeMatches& input, const RobustFitConfig& config) {
  return fitFundamentalMatrix(input, cv::USAC_MAGSAC, config);
}

}  // namespace sift_hull
