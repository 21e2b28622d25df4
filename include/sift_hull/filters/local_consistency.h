#pragma once

#include "sift_hull/features/matching.h"
#include "sift_hull/filters/filter_result.h"
#include "sift_hull/settings.h"

namespace sift_hull {

/// Local similarity consistency ("lsc"): a SIFT match carries a similarity transform, its scale
/// ratio s = size_right / size_left and its rotation a = angle_right - angle_left. For a correct
/// match it predicts where each nearby correct match lands: q_n ~ q_m + s R(a) (p_n - p_m), and
/// back, p_n ~ p_m + R(-a) (q_n - q_m) / s. Score: the share of the match's lsc_neighbours nearest
/// matches in the left image, and of those in the right image, that land within
/// lsc_max_relative_error of their distance (plus lsc_min_tolerance_px) of the prediction. Kept
/// when the score is at least lsc_min_support. O(N K). Invariant to rotating, scaling and shifting
/// either image; uses no geometry of the pair, so it holds for several motions and for planes.
struct LscConfig {
  int neighbours = 16;               ///< K: nearest matches looked at in each image
  double max_relative_error = 0.35;  ///< tolerance as a share of the neighbour's distance
  double min_tolerance_px = 2.0;     ///< tolerance floor, px
  double min_support = 0.25;         ///< kept when at least this share of neighbours agrees
};
/// Its settings: names, units, ranges, help (sift_hull/settings.h).
template <>
const SettingTable<LscConfig>& settingsOf<LscConfig>();

/// Throws std::invalid_argument naming the first bad field.
void validate(const LscConfig& config);
FilterResult filterLsc(const PutativeMatches& input, const LscConfig& config);

/// GSC restricted to neighbourhoods ("local_gsc"): the paper's 8-sector polar-angle histograms,
/// from each keypoint's orientation, over the match's local_gsc_neighbours nearest matches in the
/// left image together with its nearest in the right image (the same set of matches in both
/// histograms, as in GSC). Score: the histograms' Euclidean distance (0 to sqrt(2)); kept when at
/// most local_gsc_max_histogram_distance. Robust to perspective, which bends GSC's global layout.
/// O(N K).
struct LocalGscConfig {
  int neighbours = 16;
  double max_histogram_distance = 0.35;
};
/// Its settings: names, units, ranges, help (sift_hull/settings.h).
template <>
const SettingTable<LocalGscConfig>& settingsOf<LocalGscConfig>();

void validate(const LocalGscConfig& config);
FilterResult filterLocalGsc(const PutativeMatches& input, const LocalGscConfig& config);

}  // namespace sift_hull
