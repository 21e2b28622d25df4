#pragma once

#include <cstdint>
#include <opencv2/core.hpp>

#include "sift_hull/geometry/camera.h"
#include "sift_hull/hull/octree.h"
#include "sift_hull/refine/surface_points.h"

namespace sift_hull {

/// Dense correspondences of a calibrated pair along the epipolar lines: every grid_step_px-th
/// pixel of the left image whose line of sight crosses the hull is searched for along the part
/// of its epipolar line that the hull spans, by the normalised cross-correlation (NCC) of a patch
/// mapped into the right view (the local affine map of a plane facing the left camera, which
/// follows the pair's rotation and scale); a match must be clearly the best along the line and
/// lead back to its left pixel when searched for from the right. Where SIFT finds few features
/// (the inside of a cavity, seen steeply by a few views) this gives the surface points that the
/// free-space carving needs.
struct DenseMatchConfig {
  /// Spacing of the left pixels searched for, pixels; 0 (the default) turns dense matching off.
  /// Off by default: on Middlebury's dino and temple, dense matches (4) lower the mean
  /// reprojection IoU after carving by 0.0015 and 0.0048 (docs/EVALUATION.md), while SIFT's
  /// alone keep it; on the textured synthetic cup they carve 6 % of the pocket, SIFT's 0.1 %.
  int grid_step_px = 0;
  /// The patch is (2 r + 1)^2 pixels.
  int patch_radius_px = 3;
  /// Smallest NCC of a match, in (-1, 1].
  double min_ncc = 0.85;
  /// The best NCC along the line must beat every other peak (samples more than a patch away from
  /// it) by this much.
  double min_ncc_margin = 0.1;
  /// Patches flatter than this (standard deviation of the grey level, 0..1) are not searched.
  double min_patch_std = 0.02;
  /// The search back from the right pixel must end this close to the left pixel, pixels.
  double max_round_trip_px = 1.0;
};

/// Throws std::invalid_argument naming the first bad field.
void validate(const DenseMatchConfig& config);

/// A view as dense matching reads it: grey levels in [0, 1] and where a patch lies wholly inside
/// the silhouette. A patch that crosses the silhouette's border (the object against its
/// background) would match the contour, which is no point of the surface.
struct DenseView {
  cv::Mat grey;    ///< CV_32FC1
  cv::Mat inside;  ///< CV_8UC1, non-zero where the patch around the pixel is inside the silhouette
};

/// Takes an image of CV_8U or CV_16U with 1, 3 (BGR) or 4 (BGRA) channels and its silhouette
/// (CV_8UC1 of the same size, non-zero inside); throws std::invalid_argument for an empty image,
/// another type, a bad silhouette or a patch_radius_px outside DenseMatchConfig's range.
DenseView denseMatchingView(const cv::Mat& image, const cv::Mat& mask, int patch_radius_px);

/// The dense matches (PairMatches without keypoint ids, raw pixels) of views left_view and
/// right_view, whose images (denseMatchingView, with the config's patch_radius_px) and cameras
/// are given, searched inside the hull's occupied cells on `threads` threads; the same matches in
/// the same order for any number of threads. Empty when grid_step_px is 0. Throws
/// std::invalid_argument for a bad config or views not made by denseMatchingView.
PairMatches denseMatches(const DenseView& left_image, const DenseView& right_image,
                         const PinholeCamera& left, const PinholeCamera& right, uint32_t left_view,
                         uint32_t right_view, const VisualHull& hull,
                         const DenseMatchConfig& config, int threads);

}  // namespace sift_hull
