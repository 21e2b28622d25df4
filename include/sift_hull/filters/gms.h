#pragma once

#include "sift_hull/features/matching.h"
#include "sift_hull/filters/filter_result.h"
#include "sift_hull/settings.h"

namespace sift_hull {

/// Grid-based Motion Statistics (Bian et al., CVPR 2017). Score: the support of the match's cell
/// pair divided by the cell's threshold, so a match is kept when its score exceeds 1.
struct GmsConfig {
  int grid_cells = 20;            ///< cells per image side (the paper's G = 20 x 20)
  double threshold_factor = 6.0;  ///< alpha in tau = alpha * sqrt(n)
  bool with_rotation = false;     ///< try the 8 rotations of the 3x3 neighbourhood
  bool with_scale = false;        ///< try 5 relative grid scales of the right image
};
/// Its settings: names, units, ranges, help (sift_hull/settings.h).
template <>
const SettingTable<GmsConfig>& settingsOf<GmsConfig>();
/// Throws std::invalid_argument for a setting outside its range.
void validate(const GmsConfig& config);

FilterResult filterGms(const PutativeMatches& input, const GmsConfig& config);

}  // namespace sift_hull
