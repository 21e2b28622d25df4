#pragma once

#include <opencv2/core.hpp>
#include <string>
#include <vector>

#include "sift_hull/features/matching.h"
#include "sift_hull/filters/filter_result.h"
#include "sift_hull/settings.h"

namespace sift_hull {

/// cv::findFundamentalMat through OpenCV's USAC: plain RANSAC ("ransac") or MAGSAC ("magsac").
/// Score: the larger of the two point-to-epipolar-line distances under the estimated F, in pixels
/// (NaN when no F was found). Fewer than 8 valid matches: none kept. Held twice in FilterConfigs:
/// its settings are named ransac_<field> and magsac_<field>.
struct RobustFitConfig {
  double max_epipolar_px = 1.0;
  double confidence = 0.99;
  int max_iterations = 1000;
  /// The sampler's random state (OpenCV's UsacParams::randomGeneratorState): the same seed, the
  /// same answer; evaluate-filters reports the mean over seeds 0 to 4.
  int seed = 0;
};
/// Its settings: names, units, ranges, help (sift_hull/settings.h).
template <>
const SettingTable<RobustFitConfig>& settingsOf<RobustFitConfig>();

/// F between the points of the valid matches by MAGSAC (OpenCV's USAC with the settings of its
/// USAC_MAGSAC flag and config.seed); empty when there are fewer than 8 or it fails.
cv::Mat magsacFundamentalMatrix(const std::vector<cv::Point2f>& left,
                                const std::vector<cv::Point2f>& right,
                                const RobustFitConfig& config);
/// The same for a homography (4 points at least), inlier threshold max_transfer_px.
cv::Mat magsacHomography(const std::vector<cv::Point2f>& left,
                         const std::vector<cv::Point2f>& right, double max_transfer_px,
                         const RobustFitConfig& config);

FilterResult filterRansac(const PutativeMatches& input, const RobustFitConfig& config);
FilterResult filterMagsac(const PutativeMatches& input, const RobustFitConfig& config);

/// Throws std::invalid_argument naming `name` and the first bad field.
void validate(const RobustFitConfig& config, const std::string& name);

}  // namespace sift_hull
