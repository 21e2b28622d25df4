#pragma once

#include <Eigen/Core>

#include "sift_hull/features/matching.h"
#include "sift_hull/filters/filter_result.h"
#include "sift_hull/settings.h"

namespace sift_hull {

/// Keeps a match when each point lies within max_distance_px of the other's epipolar line under
/// the calibrated F, checked in both images ("reverse validation"). Score: the larger of the two
/// point-to-line distances, in pixels. Needs PutativeMatches::F_right_left; with
/// PutativeMatches::cameras, the points are undistorted first (F relates ideal pixels) and each
/// distance is taken back to raw pixels by the lens's local magnification, so max_distance_px
/// means pixels of the images as taken; a point beyond where the lens model can be inverted is
/// rejected (score NaN).
struct EpipolarConfig {
  double max_distance_px = 2.0;
};
/// Its settings: names, units, ranges, help (sift_hull/settings.h).
template <>
const SettingTable<EpipolarConfig>& settingsOf<EpipolarConfig>();

FilterResult filterEpipolar(const PutativeMatches& input, const EpipolarConfig& config);

/// Keeps each match with finite positions whose symmetric epipolar distance under F_right_left is
/// at most max_px; score: the larger of the two point-to-line distances. Shared by the filters that
/// estimate F.
FilterResult keepNearEpipolarLines(const PutativeMatches& input,
                                   const Eigen::Matrix3d& F_right_left, double max_px);

}  // namespace sift_hull
