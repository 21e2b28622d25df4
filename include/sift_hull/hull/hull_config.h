#pragma once

#include "sift_hull/settings.h"

namespace sift_hull {

/// Octree carving settings.
struct HullConfig {
  /// Octree levels below the root cube; resolution = cube edge / 2^max_depth, the cube the box's
  /// longest edge plus three cells (HullCube::around).
  int max_depth = 8;
  /// Finest cell edge in metres (octomap_server's `resolution`); > 0 replaces max_depth by the
  /// least depth whose cube of such cells covers the box (HullCube::withResolution). 0: from
  /// max_depth.
  double resolution_m = 0.0;
  /// Whether a view carves what it sees outside its image. When false, a view keeps the points
  /// seen beyond a side of its image where the border cuts its silhouette (the object may go on
  /// there), and carves the rest; see SignedDistanceMap.
  bool carve_outside_image = false;
  /// Added to a cell's projected radius before comparing with the signed distance: covers the error
  /// of the pixel-sampled, interpolated transform.
  double distance_slack_px = 1.0;
  int padding_px = 16;  ///< around each distance map (see SignedDistanceMap)
  /// Image pixels per side of one element of a view's distance map in buildHull and, once it has
  /// its box, in HullStream: 0 chooses it per view (distanceReduction(): a finest voxel covers about one element; 1 for views whose
  /// voxels cover under two pixels and for images under 2 MP), 1 forces the full-resolution
  /// transform, 2 to 15 force that factor. A reduced map is exact at its samples near the
  /// contour and adds its error bound (at most the factor, in pixels;
  /// reducedDistanceErrorBound_px) to distance_slack_px for that view. makeHullViews, and
  /// HullStream's views waiting for a box, use full resolution.
  int distance_reduction = 0;
  int threads = 2;  ///< for carving and for the mesh's field samples
};
/// Its settings: names, units, ranges, help (sift_hull/settings.h).
template <>
const SettingTable<HullConfig>& settingsOf<HullConfig>();

/// Throws std::invalid_argument naming the first bad field.
void validate(const HullConfig& config);

}  // namespace sift_hull
