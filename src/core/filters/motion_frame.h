#pragma once

// The SIFT frame a motion's matches share (vote_ransac.cpp: the medians of the vote that chose
// where its samples were drawn), against which a match that only a fundamental matrix explains
// is checked.

#include <cmath>
#include <vector>

namespace sift_hull {
namespace detail {

/// A match explained by a fundamental matrix whose SIFT rotation differs from its motion's turn
/// by more than this is not kept: the epipolar constraint places its right point only on a line,
/// and a patch turned more than a quarter turn against the rest of the motion is one that SIFT
/// found elsewhere along that line (repeated texture), not the same surface seen again. A
/// correct match's turn departs from its motion's by the perspective of its surface, well under
/// a quarter turn at any baseline the matcher can bridge.
constexpr double kMaxTurnFromMotionDeg = 90.0;
/// Likewise for the scale change, in octaves: a surface seen four times larger or smaller than
/// the rest of its motion.
constexpr double kMaxOctavesFromMotion = 2.0;

/// The turn (deg, in [0, 360)) and the log2 scale change that a motion's matches share, with the
/// scale ratios kMaxOctavesFromMotion away from it. NaN where unknown.
struct MotionFrame {
  float turn_deg = NAN;
  float log2_scale = NAN;
  float min_scale_ratio = NAN, max_scale_ratio = NAN;
};

/// The frame of a turn (deg) and a log2 scale change; either may be NaN (unknown).
MotionFrame motionFrame(float turn_deg, float log2_scale);

/// Each match's SIFT frame as frameAgrees reads it: right angle - left angle (deg, in (-360,
/// 360); NaN when either keypoint has no orientation, OpenCV's -1) and right size / left size
/// (NaN when either is not positive).
struct MatchFrames {
  std::vector<float> turn_deg, scale_ratio;
  void resize(size_t n) { turn_deg.resize(n), scale_ratio.resize(n); }
  /// Match k's frame from its keypoints' angles (deg) and sizes.
  void set(size_t k, float left_angle_deg, float left_size, float right_angle_deg,
           float right_size) {
    const bool oriented = (left_angle_deg >= 0.f) & (left_angle_deg < 360.f) &
                          (right_angle_deg >= 0.f) & (right_angle_deg < 360.f);
    const bool sized = (left_size > 0.f) & (right_size > 0.f);
    turn_deg[k] = oriented ? right_angle_deg - left_angle_deg : NAN;
    scale_ratio[k] = sized ? right_size / left_size : NAN;
  }
};

/// Whether a match's frame (MatchFrames' turn and scale ratio) lies within kMaxTurnFromMotionDeg
/// and kMaxOctavesFromMotion of the motion's; true where the match's or the frame's value is
/// unknown. Comparisons only, combined with & rather than && (no logarithm, no remainder, no
/// branch), so that a loop over the matches vectorises.
inline bool frameAgrees(const MotionFrame& frame, float turn_deg, float scale_ratio) {
  constexpr float q = static_cast<float>(kMaxTurnFromMotionDeg);
  const float d = turn_deg - frame.turn_deg;  // in (-720, 360): away in three intervals
  const bool away = ((d > q) & (d < 360.f - q)) | ((d > q - 360.f) & (d < -q)) |
                    ((d > q - 720.f) & (d < -360.f - q));
  // NaN (either turn unknown) fails every comparison; a huge right size gives an infinite ratio.
  return !away & !(scale_ratio < frame.min_scale_ratio) & !(scale_ratio > frame.max_scale_ratio);
}

}  // namespace detail
}  // namespace sift_hull
