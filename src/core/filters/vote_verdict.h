#pragma once

// The final verdict of vote_ransac (and best) on every putative match, given the motions found:
// each motion's residual in the units guided_tolerance_scale names, the SIFT frame of a match a
// fundamental matrix explains (motion_frame.h), and one left point per right keypoint.

#include <cstdint>
#include <vector>

#include "filters/motion_frame.h"
#include "sift_hull/features/matching.h"
#include "sift_hull/filters/filter_result.h"
#include "sift_hull/filters/two_view_models.h"
#include "sift_hull/filters/vote_ransac.h"

namespace sift_hull {
namespace detail {

/// The residual threshold of a motion, px.
inline double motionThreshold(const TwoViewModel& motion, const VoteRansacFilterConfig& config) {
  return motion.homography ? config.guided.max_transfer_px : config.magsac.max_epipolar_px;
}

/// Every match judged against the motions (float residuals, vectorised): kept when a motion
/// explains it within its threshold, in the units guided_tolerance_scale names (for a
/// fundamental matrix, which places the right point only on a line, also when its SIFT frame
/// agrees with the motion's, and it is the one such match of its right keypoint:
/// keepUniqueImages). `all` holds the finite matches, `index` their indices into input.matches,
/// `match_frames` their frames; `frames` one per motion. Writes score and keep of those matches.
void judgeMatches(const PutativeMatches& input, const PointPairs& all,
                  const std::vector<size_t>& index, const std::vector<TwoViewModel>& motions,
                  const std::vector<MotionFrame>& frames, const MatchFrames& match_frames,
                  const VoteRansacFilterConfig& config, FilterResult* result);

/// A right keypoint is the image of one place: where matches whose `kept` entry equals
/// `candidate` (by position in `index`) come from left points apart from each other and share a
/// right keypoint, only the one with the smallest descriptor distance keeps its entry (ties: the
/// first); the others' become 0. Two left points are apart when their distance exceeds both
/// keypoints' sizes (their patches do not overlap); SIFT's keypoints of several orientations at
/// one place, or a left image finer than the right, are not apart. Matches whose right keypoint
/// index is out of range, or whose sizes are unknown, are left as they are.
/// O(N + right keypoints).
void keepUniqueImages(const PutativeMatches& input, const std::vector<size_t>& index,
                      uint8_t candidate, std::vector<uint8_t>* kept);

}  // namespace detail
}  // namespace sift_hull
