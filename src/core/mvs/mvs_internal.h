#pragma once

// The stages of photo carving (sift_hull/mvs/photo_carving.h), shared by its source files.

#include <Eigen/Core>
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>
#include <opencv2/core.hpp>
#include <vector>

#include "sift_hull/geometry/camera.h"
#include "sift_hull/hull/octree.h"
#include "sift_hull/mvs/photo_carving.h"

namespace sift_hull {
namespace detail {

/// The share of a view's width and height its depth map has: the finest voxel at `centre_W` spans
/// config.photo_voxel_px pixels there, at most config.photo_image_scale (and at least 1/64).
double depthMapScale(const PinholeCamera& camera, const Eigen::Vector3d& centre_W, double voxel_m,
                     const PhotoCarveConfig& config);

/// A view at the depth maps' scale, in ideal pixels (the lens distortion taken out).
struct ReducedView {
  PinholeCamera camera;  ///< scaled K, no distortion
  cv::Mat grey;          ///< CV_32FC1 in [0, 1]
  cv::Mat inside;        ///< CV_8UC1, non-zero where a patch lies wholly inside the silhouette
};

/// Throws std::invalid_argument for an empty image or one of another size than the mask's.
ReducedView reducedView(const PinholeCamera& camera, const cv::Mat& image, const cv::Mat& mask,
                        double scale, int patch_radius_px);

/// Each view's neighbours: up to `count` other views whose lines of sight to `centre_W` make the
/// smallest angles with its own, none beyond max_angle_deg; ties by index.
std::vector<std::vector<uint32_t>> chooseNeighbours(const std::vector<PinholeCamera>& cameras,
                                                    const Eigen::Vector3d& centre_W, int count,
                                                    double max_angle_deg);

/// The hull's depth range at each pixel of a view: the nearest and farthest corner depths of the
/// occupied leaves whose projected corners' box holds the pixel (NaN where none does).
struct DepthRange {
  cv::Mat near_m, far_m;            ///< CV_32FC1
  double min_m = 0.0, max_m = 0.0;  ///< over the image; 0 when nothing projects into it
};
DepthRange hullDepthRange(const std::vector<HullCell>& occupied, const HullCube& cube,
                          const PinholeCamera& camera, cv::Size size);

/// The plane sweep of view `view` against its neighbours: each pixel's best depth within its
/// range (refined between planes by a parabola through the scores) and its score, NaN where no
/// plane is scored (outside the silhouette, a flat patch, no neighbour sees it). Adds the sweeps
/// made to *sweeps.
void sweepDepth(const std::vector<ReducedView>& views, uint32_t view,
                const std::vector<uint32_t>& neighbours, const DepthRange& range,
                const PhotoCarveConfig& config, double voxel_m, cv::Mat* depth_m, cv::Mat* ncc,
                size_t* sweeps);

/// Slanted-plane PatchMatch from the sweep's depths (patch_match.cpp):
/// config.photo_patch_match_rounds rounds refine *depth_m and *ncc in place, pixel by pixel inside
/// the silhouette.
void patchMatchDepth(const std::vector<ReducedView>& views, uint32_t view,
                     const std::vector<uint32_t>& neighbours, const DepthRange& range,
                     const PhotoCarveConfig& config, double voxel_m, cv::Mat* depth_m,
                     cv::Mat* ncc);

/// Keeps a pixel's depth where at least config.photo_min_consistent_views of its neighbours'
/// depth maps agree with it within config.photo_consistency_voxels.
cv::Mat consistentDepth(const std::vector<ViewDepth>& depths, uint32_t view,
                        const PhotoCarveConfig& config, double voxel_m);

/// The mean of the largest `best` (at most 8) of values[0 .. count) that are not NaN, NaN when
/// fewer are given: a depth's or a plane's score over its neighbours.
inline float bestMean(const float* values, int count, int best) {
  float top[8];
  int kept = 0;
  for (int i = 0; i < count; ++i) {
    const float v = values[i];
    if (std::isnan(v)) continue;
    int at = std::min(kept, best);
    while (at > 0 && top[at - 1] < v) {
      if (at < best) top[at] = top[at - 1];
      --at;
    }
    if (at < best) top[at] = v;
    kept = std::min(kept + 1, best);
  }
  if (kept < best) return std::numeric_limits<float>::quiet_NaN();
  float sum = 0.0f;
  for (int i = 0; i < best; ++i) sum += top[i];
  return sum / static_cast<float>(best);
}

/// Whether a leaf is occupied: an in cell, or a surface cell whose centre is inside (as
/// HullStats::occupied_volume_m3 counts them).
inline bool isOccupied(const HullCell& cell) {
  return cell.state == CellState::kIn ||
         (cell.state == CellState::kSurface && cell.centre_value <= 0.0f);
}

/// The centre of a finest voxel (indices in the cube), metres.
inline Eigen::Vector3d voxelCentre(const HullCube& cube, const Eigen::Vector3i& voxel) {
  return cube.origin_W() + (voxel.cast<double>().array() + 0.5).matrix() * cube.resolution_m;
}

/// The occupied leaves of the hull (isOccupied).
std::vector<HullCell> occupiedLeaves(const VisualHull& hull);

}  // namespace detail
}  // namespace sift_hull
