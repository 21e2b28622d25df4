#include "sift_hull/filters/guided.h"

#include <algorithm>
#include <cmath>
#include <opencv2/core/eigen.hpp>
#include <optional>
#include <random>
#include <stdexcept>
#include <string>
#include <vector>

#include "sift_hull/filters/epipolar.h"
#include "sift_hull/filters/scaled_residuals.h"
#include "sift_hull/geometry/camera.h"

namespace sift_hull {
namespace {

/// One motion: a fundamental matrix or a homography (right = H left).
struct Motion {
  bool homography = false;
  Eigen::Matrix3d matrix = Eigen::Matrix3d::Zero();
};

double transferError(const Eigen::Matrix3d& H, const cv::Point2f& a, const cv::Point2f& b) {
  const Eigen::Vector3d forward = H * Eigen::Vector3d(a.x, a.y, 1.0);
  const Eigen::Vector3d backward = H.inverse() * Eigen::Vector3d(b.x, b.y, 1.0);
  const double f = (forward.hnormalized() - Eigen::Vector2d(b.x, b.y)).norm();
  const double g = (backward.hnormalized() - Eigen::Vector2d(a.x, a.y)).norm();
  return std::isfinite(f) && std::isfinite(g) ? std::max(f, g) : INFINITY;
}

/// The motion's residual for one match, px; a match explained when within its threshold.
double residual(const Motion& motion, const cv::Point2f& a, const cv::Point2f& b) {
  if (motion.homography) return transferError(motion.matrix, a, b);
  return epipolarDistances(motion.matrix, {a.x, a.y}, {b.x, b.y}).max();
}

double thresholdOf(const Motion& motion, const GuidedFilterConfig& config) {
  return motion.homography ? config.guided.max_transfer_px : config.magsac.max_epipolar_px;
}

bool explains(const Motion& motion, const cv::Point2f& a, const cv::Point2f& b,
              const GuidedFilterConfig& config) {
  return residual(motion, a, b) <= thresholdOf(motion, config);
}

/// The better motion (F or H) for the points, when any fits at least guided_min_model_inliers.
std::optional<Motion> fitMotion(const std::vector<cv::Point2f>& left,
                                const std::vector<cv::Point2f>& right,
                                const GuidedFilterConfig& config, size_t* inliers) {
  const cv::Mat F = magsacFundamentalMatrix(left, right, config.magsac);
  const cv::Mat H = magsacHomography(left, right, config.guided.max_transfer_px, config.magsac);
  std::optional<Motion> fundamental, homography;
  if (F.rows >= 3 && F.cols == 3) {
    fundamental = Motion{};
    cv::cv2eigen(F.rowRange(0, 3), fundamental->matrix);
  }
  if (H.rows == 3 && H.cols == 3) {
    homography = Motion{};
    homography->homography = true;
    cv::cv2eigen(H, homography->matrix);
  }
  size_t count[2] = {0, 0};
  for (size_t i = 0; i < left.size(); ++i) {
    if (fundamental) count[0] += explains(*fundamental, left[i], right[i], config);
    if (homography) count[1] += explains(*homography, left[i], right[i], config);
  }
  const bool use_h = homography && count[1] >= config.guided.homography_share * count[0];
  *inliers = count[use_h ? 1 : 0];
  if (*inliers < static_cast<size_t>(config.guided.min_model_inliers)) return std::nullopt;
  return use_h ? homography : fundamental;
}

/// Up to guided_max_models motions, each fitted to what the earlier ones leave unexplained.
std::vector<Motion> fitMotions(std::vector<cv::Point2f> left, std::vector<cv::Point2f> right,
                               const GuidedFilterConfig& config) {
  std::vector<Motion> motions;
  while (static_cast<int>(motions.size()) < config.guided.max_models) {
    size_t inliers = 0;
    const std::optional<Motion> motion = fitMotion(left, right, config, &inliers);
    if (!motion) break;
    motions.push_back(*motion);
    std::vector<cv::Point2f> rest_left, rest_right;
    for (size_t i = 0; i < left.size(); ++i) {
      if (explains(*motion, left[i], right[i], config)) continue;
      rest_left.push_back(left[i]), rest_right.push_back(right[i]);
    }
    left.swap(rest_left), right.swap(rest_right);
  }
  return motions;
}

}  // namespace

FilterResult filterGuided(const PutativeMatches& input, const GuidedFilterConfig& config) {
  validate(config.guided);
  const FilterResult local = filterLsc(input, config.lsc);
  std::vector<size_t> kept;
  for (size_t m = 0; m < input.matches.size(); ++m) {
    if (local.keep[m]) kept.push_back(m);
  }
  const size_t sample = static_cast<size_t>(config.guided.max_fit_points);
  if (kept.size() > sample) {
    std::mt19937 random(static_cast<unsigned>(config.magsac.seed));
    std::shuffle(kept.begin(), kept.end(), random);
    kept.resize(sample);
    std::sort(kept.begin(), kept.end());
  }
  std::vector<cv::Point2f> left, right;
  for (size_t m : kept) left.push_back(input.left(m).pt), right.push_back(input.right(m).pt);
  const std::vector<Motion> motions = fitMotions(left, right, config);
  FilterResult result = FilterResult::keepingNone(input.matches.size());
  if (motions.empty()) return result;
  for (size_t m = 0; m < input.matches.size(); ++m) {
    if (!input.hasFinitePositions(m)) continue;
    const cv::Point2f &a = input.left(m).pt, &b = input.right(m).pt;
    const std::string& unit = config.guided.tolerance_scale;
    double best = INFINITY;
    bool explained = false;
    for (const Motion& motion : motions) {
      best = std::min(best, residual(motion, a, b));
      const TwoViewModel model{motion.homography, motion.matrix};
      const auto [left_interval, right_interval] =
          pairIntervals(unit, model, a.x, a.y, input.left(m).size, input.right(m).size);
      explained = explained || scaledModelResidual(model, a.x, a.y, b.x, b.y, left_interval,
                                                   right_interval) <= thresholdOf(motion, config);
    }
    result.score[m] = best;
    result.keep[m] = explained && local.score[m] >= config.guided.min_support;
  }
  return result;
}

}  // namespace sift_hull
