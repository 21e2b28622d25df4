#pragma once

#include "sift_hull/features/matching.h"
#include "sift_hull/filters/filter_result.h"
#include "sift_hull/filters/local_consistency.h"
#include "sift_hull/filters/robust_fit.h"
#include "sift_hull/settings.h"

namespace sift_hull {

/// The guided filter ("guided"): lsc first (cheap, model-free), then MAGSAC on what lsc kept, for
/// a fundamental matrix and for a homography; the homography is chosen when it explains at least
/// guided_homography_share of the fundamental matrix's inliers (planes and pure rotations, where
/// F is degenerate). Then the models again on what the first left over, up to guided_max_models
/// motions each with at least guided_min_model_inliers inliers (two objects moving differently).
/// Finally every putative match, not only lsc's survivors, is judged again: kept when a model
/// explains it (symmetric epipolar distance <= magsac_max_epipolar_px, or transfer error <=
/// guided_max_transfer_px both ways; with guided_scale_with_keypoints, each image's distance in
/// octave intervals of its keypoint) and its lsc support is at least guided_min_support.
/// Score: the smallest residual over the models, px (NaN when no model was found: none kept).
struct GuidedConfig {
  double max_transfer_px = 3.0;
  double homography_share = 0.9;
  int max_models = 2;
  int min_model_inliers = 20;
  double min_support = 0.1;
  /// MAGSAC fits its models to at most this many of lsc's survivors (a random sample drawn with
  /// magsac_seed), so that its time does not grow with N; every match is judged afterwards.
  int max_fit_points = 200;
  /// The final verdict (guided and vote_ransac) measures each image's residual in the sampling
  /// intervals of its keypoint's SIFT octave (octaveInterval_px, scaled_residuals.h): a large
  /// keypoint, located less well in pixels, is allowed as much more.
  bool scale_with_keypoints = true;
};
/// Its settings: names, units, ranges, help (sift_hull/settings.h).
template <>
const SettingTable<GuidedConfig>& settingsOf<GuidedConfig>();

/// Everything the guided filter uses: its own settings, lsc's and MAGSAC's.
struct GuidedFilterConfig {
  GuidedConfig guided;
  LscConfig lsc;
  RobustFitConfig magsac;
};

void validate(const GuidedConfig& config);
FilterResult filterGuided(const PutativeMatches& input, const GuidedFilterConfig& config);

}  // namespace sift_hull
