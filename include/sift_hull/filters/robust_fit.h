#pragma once

#include <string>

#include "sift_hull/features/matching.h"
#include "sift_hull/filters/filter_result.h"

namespace sift_hull {

/// cv::findFundamentalMat with FM_RANSAC ("ransac") or USAC_MAGSAC ("magsac"). Score: the larger
/// of the two point-to-epipolar-line distances under the estimated F, in pixels (NaN when no F
/// was found). Fewer than 8 valid matches: none kept.
/// Held twice in FilterConfigs: its settings are named ransac_<field> and magsac_<field>.
struct RobustFitConfig {
  double max_epipolar_px = 1.0;
  double confidence = 0.99;
  int max_iterations = 1000;
};

FilterResult filterRansac(const PutativeMatches& input, const RobustFitConfig& config);
FilterResult filterMagsac(const PutativeMatches& input, const RobustFitConfig& config);

/// Throws std::invalid_argument naming `name` and the first bad field.
void validate(const RobustFitConfig& config, const std::string& name);

}  // namespace sift_hull
