#pragma once

#include "sift_hull/features/matching.h"
#include "sift_hull/filters/filter_result.h"
#include "sift_hull/filters/guided.h"
#include "sift_hull/filters/robust_fit.h"
#include "sift_hull/filters/two_view_models.h"
#include "sift_hull/settings.h"

namespace sift_hull {

/// The voted LO-RANSAC filter ("vote_ransac"): what SIFT gives each match, its rotation
/// (angle_right - angle_left) and scale ratio (size_right / size_left), chooses where the robust
/// fit draws its samples; the motions it finds then judge every putative match.
/// 1. Up to vote_ransac_max_fit_points of the putatives (a random sample drawn with magsac_seed)
///    are the fit set.
/// 2. Vote: the rotation that the most matches of the fit set share within
///    vote_ransac_max_angle_deg, then among those the scale ratio the most share within a factor
///    vote_ransac_max_scale_ratio. Minimal samples are drawn from these matches only (from all
///    when fewer than 16 voted), so few are mismatches and few iterations suffice; both modes are
///    found from the data, so the choice is invariant to rotating and zooming either image.
/// 3. LO-RANSAC (two_view_models.h) for a fundamental matrix (7 points) and a homography (4
///    points), scored over the whole fit set; the homography is chosen when it explains at least
///    guided_homography_share of F's inliers (planes, pure rotations).
/// 4. Again on what the motions found so far leave unexplained, up to guided_max_models motions,
///    each with at least guided_min_model_inliers inliers and 4 times as many as it explains when
///    each left point is paired with the right point of another match (the right points shifted
///    by half the set: a model that only fits noise does not). Where chance alone explains more
///    than 1/16 of the set within the threshold (a wide threshold: no motion with mismatches
///    could explain 4 times that), the two are compared within the narrower residual where chance
///    explains 1/16, since a motion's matches lie near it and chance's spread over the band.
///    A further motion is looked for
///    only while the rotations left over still cluster (their strongest window holds at least
///    twice its share of evenly spread rotations, and at least 2 guided_min_model_inliers); it
///    is sampled locally, searched for as long as a motion explaining two thirds of its vote
///    needs (8 samples at confidence 0.99), must explain two thirds of its vote, and must not lie
///    mostly within twice the threshold of an earlier motion (that one's leftovers).
/// 5. When the fit set was a sample, each motion is refined against all the putatives: the
///    ones within three times its threshold that no earlier motion explains (at most 512,
///    evenly spread) go to polishTwoViewModel, so that a motion fitted to a few hundred matches
///    does not lose the others at its edges, at a cost of a few residuals per putative. With
///    more than 512 near, its score is that of the sample, so a few matches at the threshold's
///    edge may change sides, as in the fit itself.
/// 6. Every putative is judged: kept when a motion explains it (symmetric epipolar distance <=
///    magsac_max_epipolar_px, transfer error <= guided_max_transfer_px both ways), each image's
///    distance scaled as guided_tolerance_scale says (by default the homography's local scale
///    there; scaled_residuals.h). A fundamental matrix places the right point only on a line: a
///    match it explains is kept only when its SIFT rotation and scale ratio also lie within a
///    quarter turn and two octaves of the ones the vote found for its motion (motion_frame.h),
///    and when no match from a left point elsewhere with a smaller descriptor distance shares
///    its right keypoint (vote_verdict.h).
/// Score: the smallest residual over the motions, px (NaN when none was found: none kept).
/// Its time hardly grows with N beyond the fit set: steps 5 and 6 are a few residuals per match.
struct VoteRansacConfig {
  double max_angle_deg = 30.0;   ///< half width of the rotation vote's window, deg
  double max_scale_ratio = 2.0;  ///< half width of the scale vote's window (factor)
  int max_fit_points = 500;      ///< size of the fit set (a random sample)
};
/// Its settings: names, units, ranges, help (sift_hull/settings.h).
template <>
const SettingTable<VoteRansacConfig>& settingsOf<VoteRansacConfig>();

/// Everything the filter uses: its vote, the motion settings it shares with guided and the fit
/// settings it shares with magsac (threshold, confidence, iterations, seed).
struct VoteRansacFilterConfig {
  VoteRansacConfig vote_ransac;
  GuidedConfig guided;
  RobustFitConfig magsac;
};

/// Throws std::invalid_argument naming the first bad field.
void validate(const VoteRansacConfig& config);
FilterResult filterVoteRansac(const PutativeMatches& input, const VoteRansacFilterConfig& config);
/// Steps 1 to 5 alone: the motions found (none, one or up to guided_max_models), in pixels.
std::vector<TwoViewModel> voteRansacMotions(const PutativeMatches& input,
                                            const VoteRansacFilterConfig& config);

}  // namespace sift_hull
