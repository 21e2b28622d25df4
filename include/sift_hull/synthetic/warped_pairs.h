#pragma once

#include <Eigen/Core>
#include <opencv2/core.hpp>
#include <vector>

#include "sift_hull/features/labelled_matches.h"
#include "sift_hull/features/matching.h"

namespace sift_hull {

/// A synthetic pair with exact ground truth made by warping one rendered view (the default scene
/// on its textured background, 640x480): regions of the left image, each moved to the right one
/// by its own homography, the later drawn over the earlier.
struct WarpedPair {
  cv::Mat left, right;                   ///< CV_8UC3
  std::vector<Eigen::Matrix3d> motions;  ///< per region: right = H left
  cv::Mat left_region;                   ///< CV_8UC1: the region of each left pixel
  cv::Mat right_owner;                   ///< CV_8UC1: 1 + the region seen at a right pixel, 0: none
};

/// The whole view turned by rotation_deg and scaled by `scale` about the image centre.
WarpedPair rotationZoomPair(double rotation_deg, double scale);

/// An optical zoom by `zoom` (1 to 12) with a turn by rotation_deg: the view rendered at `zoom`
/// times 640x480, the left image that render reduced by area to 640x480, the right one its centre
/// at the render's own resolution (no interpolated detail), turned about the image centre. SIFT
/// finds a match's keypoints `zoom` times larger on the right. Renders one view of up to 7680 px.
WarpedPair opticalZoomPair(double rotation_deg, double zoom);

/// Two objects moving differently: the view's left half and right half, each moved by its own
/// rotation, scale and shift, so that no single F or H explains the pair.
WarpedPair twoMotionPair();

/// Correct when the right point is within max_error_px of H x_left for the left
/// point's region and that region is what the right image shows there; otherwise wrong (moved out
/// of the image or hidden by the other region).
std::vector<MatchTruth> judgeByMotions(const PutativeMatches& input, const WarpedPair& pair,
                                       double max_error_px = 3.0);

}  // namespace sift_hull
