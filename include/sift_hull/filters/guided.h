#pragma once

#include <string>

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
/// guided_max_transfer_px both ways, scaled in each image as guided_tolerance_scale says) and its
/// lsc support is at least guided_min_support.
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
  /// What the final verdict (guided and vote_ransac) measures each image's residual in
  /// (scaled_residuals.h): "pixels"; "model", the homography's local scale (a left point located
  /// to a pixel lands within s pixels on the right: there the tolerance is s times as wide);
  /// "keypoints", the sampling interval of each keypoint's SIFT octave.
  std::string tolerance_scale = "model";
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
