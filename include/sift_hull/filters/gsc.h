#pragma once

#include <array>
#include <cstddef>

#include "sift_hull/features/matching.h"
#include "sift_hull/filters/filter_result.h"
#include "sift_hull/settings.h"

namespace sift_hull {

/// The global scale-invariant constraint. Score: the Euclidean distance between the match's
/// normalised left and right polar-angle histograms (0 to sqrt(2)).
struct GscConfig {
  double max_histogram_distance = 0.2;
  int threads = 0;  ///< 0 uses all hardware threads
  /// 0: the exact filter (every other match in each histogram). M > 0: each histogram over a
  /// fixed random sample of M matches (the same matches in both images, so that a correct match
  /// sees the same sampled points left and right), O(N M) instead of O(N^2).
  int max_support = 0;
};
/// Its settings: names, units, ranges, help (sift_hull/settings.h).
template <>
const SettingTable<GscConfig>& settingsOf<GscConfig>();

FilterResult filterGsc(const PutativeMatches& input, const GscConfig& config);

/// Number of polar-angle sectors of the GSC histogram (45 degrees each).
inline constexpr int kGscSectors = 8;
using GscHistogram = std::array<double, kGscSectors>;

/// The normalised left and right GSC histograms of one match, for display and checks.
struct GscHistograms {
  GscHistogram left{};
  GscHistogram right{};
  double distance() const;
};
GscHistograms gscHistograms(const PutativeMatches& input, size_t match);

}  // namespace sift_hull
