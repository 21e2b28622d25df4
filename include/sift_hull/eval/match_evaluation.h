#pragma once

#include <Eigen/Core>
#include <opencv2/core.hpp>
#include <string>
#include <vector>

#include "sift_hull/features/labelled_matches.h"
#include "sift_hull/filters/filter.h"
#include "sift_hull/geometry/correspondence.h"

namespace sift_hull {

/// Tolerances of the ground-truth checks, in pixels.
struct TruthTolerances {
  double max_row_error_px = 1.0;         ///< rectified stereo: |y_r - y_l|
  double max_column_error_px = 2.0;      ///< rectified stereo: |x_r - (x_l - d)|
  double max_homography_error_px = 3.0;  ///< || H x_l - x_r ||
  double max_scene_error_px = 2.0;       ///< synthetic scene: distance to the depth-based position
};

/// Rectified stereo: correct when the right point lies on the left point's row (within
/// max_row_error_px) at the ground-truth disparity (within max_column_error_px). The left image's
/// disparity is looked up at the nearest pixel; 0 or outside the image gives kUnknown.
std::vector<MatchTruth> judgeByDisparity(const PutativeMatches& input, const cv::Mat& disparity_px,
                                         const TruthTolerances& tolerances = {});

/// Planar scene: correct when the right point is within max_homography_error_px of H x_left (H
/// up to scale and sign).
std::vector<MatchTruth> judgeByHomography(const PutativeMatches& input,
                                          const Eigen::Matrix3d& H_right_left,
                                          const TruthTolerances& tolerances = {});

/// Synthetic scene with depth maps: correct when the left point is seen in the right view
/// within max_scene_error_px of the right point; occluded or out of view: wrong; a left point on
/// the background: kUnknown.
std::vector<MatchTruth> judgeBySceneDepth(const PutativeMatches& input, const DepthView& left,
                                          const DepthView& right,
                                          const TruthTolerances& tolerances = {});

/// Matches of a rectified pair of image files (F of a rectified pair), judged by the left image's
/// disparity map (readDisparity with `disparity_scale`). Throws when a file is missing.
LabelledMatches matchRectifiedPair(const std::string& left_path, const std::string& right_path,
                                   const std::string& disparity_path, double disparity_scale,
                                   const SiftConfig& sift, const MatchConfig& matching);
/// Matches of two views of a plane, judged by the homography file (readHomography) that maps the
/// left image to the right one; no calibration. Throws when a file is missing.
LabelledMatches matchPlanarPair(const std::string& left_path, const std::string& right_path,
                                const std::string& homography_path, const SiftConfig& sift,
                                const MatchConfig& matching);

/// A filter's result measured against the ground truth.
struct FilterScores {
  size_t putative = 0, kept = 0;
  size_t correct_putative = 0, correct_kept = 0;
  size_t wrong_putative = 0, wrong_kept = 0;
  size_t unknown_putative = 0, unknown_kept = 0;

  double precision() const;  ///< correct kept / (correct + wrong) kept; NaN when none kept
  double recall() const;     ///< correct kept / correct putative; NaN when none correct
  double f1() const;         ///< NaN when precision or recall is
  size_t mismatchesRemoved() const { return wrong_putative - wrong_kept; }
};

/// Throws std::invalid_argument when the sizes differ.
FilterScores scoreFilter(const std::vector<MatchTruth>& truth, const FilterResult& result);

}  // namespace sift_hull
