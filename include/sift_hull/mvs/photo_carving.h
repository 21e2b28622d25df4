#pragma once

#include <Eigen/Core>
#include <cstdint>
#include <functional>
#include <opencv2/core.hpp>
#include <vector>

#include "sift_hull/geometry/camera.h"
#include "sift_hull/hull/octree.h"
#include "sift_hull/settings.h"

namespace sift_hull {

/// Carving the hull by dense multi-view depth ("virtual engraving"): a depth map per view by a
/// plane sweep within the hull's depth range at each pixel (normalised cross-correlation of grey
/// patches with the best of the view's neighbours), kept where the neighbours' depth maps agree
/// (geometric consistency), then every occupied finest voxel that several views see in front of
/// their depth is free, except where a silhouette pixel's line of sight would be left with no
/// occupied voxel clear of free ones (the mesh cuts into a voxel next to free space).
struct PhotoCarveConfig {
  /// Views each view's depth is measured against: the nearest by the angle between their lines
  /// of sight to the hull's centre.
  int photo_neighbours = 6;
  /// Neighbours seen at a larger angle than this from the view are not used.
  double photo_max_neighbour_angle_deg = 75.0;
  /// The depth maps' largest resolution, as a share of the images' width and height.
  double photo_image_scale = 1.0;
  /// Each view's depth map is reduced until the finest voxel at the hull's centre spans this many
  /// of its pixels (never beyond photo_image_scale): the depth maps' resolution follows the
  /// octree's, not the images'.
  double photo_voxel_px = 1.0;
  /// Patches of (2 r + 1)^2 pixels at that resolution.
  int photo_patch_radius_px = 2;
  /// A pixel's score at a depth is the mean NCC of its best this many neighbours there.
  int photo_best_neighbours = 1;
  /// Smallest score of a pixel's depth.
  double photo_min_ncc = 0.5;
  /// Patches flatter than this (standard deviation of the grey level, 0..1) get no depth.
  double photo_min_patch_std = 0.01;
  /// Depths swept per view, evenly in inverse depth over the hull's depth range in that view.
  int photo_depth_planes = 64;
  /// Rounds of slanted-plane PatchMatch after the sweep (0: the sweep's fronto-parallel depths).
  int photo_patch_match_rounds = 4;
  /// A depth agrees with a neighbour's depth map within this many finest voxels.
  double photo_consistency_voxels = 2.0;
  /// Neighbours whose depth maps must agree with a pixel's depth for it to be kept.
  int photo_min_consistent_views = 1;
  /// A voxel centre must lie this many finest voxels in front of a view's depth to be empty for it.
  double photo_margin_voxels = 1.0;
  /// Views that must see a voxel empty (and more of them than see the surface there) before it
  /// is free.
  int photo_min_views = 2;
};
/// Its settings: names, units, ranges, help (sift_hull/settings.h).
template <>
const SettingTable<PhotoCarveConfig>& settingsOf<PhotoCarveConfig>();

/// Throws std::invalid_argument naming the first bad field.
void validate(const PhotoCarveConfig& config);

/// The views photo carving reads: cameras in the hull's frame (raw pixels), and each view's image
/// (8-bit grey, BGR or BGRA, of its camera's size) and silhouette (CV_8UC1, non-zero inside), each
/// asked for once.
struct PhotoViews {
  std::vector<PinholeCamera> cameras;
  std::function<cv::Mat(uint32_t)> image;
  std::function<cv::Mat(uint32_t)> mask;
};

/// One view's depth map at the configured scale, in the ideal (undistorted) pixels of `camera`.
struct ViewDepth {
  PinholeCamera camera;  ///< the view's camera at that scale, without distortion
  cv::Mat depth_m;       ///< CV_32FC1, NaN where no depth was kept
  cv::Mat ncc;           ///< CV_32FC1, the kept depth's score (NaN elsewhere)
  std::vector<uint32_t> neighbours;
};

struct PhotoCarveResult {
  std::vector<ViewDepth> depths;  ///< one per view, after the consistency check
  /// The finest voxels found empty, in z, y, x order, for VisualHull::carveFree.
  std::vector<Eigen::Vector3i> free_voxels;
  double scale_min = 0.0, scale_max = 0.0;  ///< the depth maps' scales over the views
  size_t sweeps = 0;                        ///< plane sweeps made (views x neighbours x planes)
  size_t depth_pixels = 0;                  ///< pixels with a depth, before the consistency check
  size_t consistent_pixels = 0;             ///< and after it
  size_t restored_voxels = 0;  ///< voxels left occupied because a silhouette pixel needs them
  double depth_ms = 0.0, consistency_ms = 0.0, voting_ms = 0.0, silhouettes_ms = 0.0;
};

/// Photo carving of `hull` (PhotoCarveConfig) on the hull's threads; the same result for any
/// number of threads. Throws std::invalid_argument for a bad config, fewer than two views, or an
/// image or silhouette that does not fit its camera.
PhotoCarveResult photoCarve(const VisualHull& hull, const PhotoViews& views,
                            const PhotoCarveConfig& config);

}  // namespace sift_hull
