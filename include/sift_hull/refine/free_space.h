#pragma once

#include <Eigen/Core>
#include <memory>
#include <vector>

#include "sift_hull/geometry/camera.h"
#include "sift_hull/hull/octree.h"
#include "sift_hull/refine/surface_points.h"
#include "sift_hull/settings.h"

namespace sift_hull {

/// Which voxels the lines of sight to surface points make free. Each view's points are joined
/// into a surface by a Delaunay triangulation of their projections; that surface's depth map
/// bounds what the view sees as empty. Triangles longer than max_edge_fraction of the cube's
/// edge or seen more obliquely than max_slant_deg (across a depth jump, from a rim down to the
/// floor of a cavity) are left out.
struct FreeSpaceConfig {
  /// A voxel's centre must lie this many finest voxels, plus two of the surface's depth_sigma_m
  /// and its bulge (below), in front of a view's surface to be empty for that view: the surface
  /// and its uncertainty stay.
  double stop_margin_voxels = 3.0;
  /// Views that must see a voxel empty before it is free. One suffices by default: what a view
  /// sees empty ends on a triangle of three surface points, each of which passed the reprojection,
  /// hull and track tests and agrees in depth with the median of its Delaunay neighbours in that
  /// view (a lone wrong point is dropped there). 2 asks two views to agree as well.
  int min_views = 1;
  /// Voxels whose centre lies this close to a surface point (finest voxels) are never free.
  double keep_radius_voxels = 1.5;
  /// Longest edge of a triangle of a view's surface, as a fraction of the cube's edge.
  double max_edge_fraction = 0.08;
  /// Largest angle between a triangle's normal and the line of sight to it, degrees: a triangle
  /// seen edge-on spans a depth jump (a column in front of a wall) more often than a surface.
  double max_slant_deg = 75.0;
  /// The surface between a triangle's corners may bulge towards the camera by this fraction of
  /// the triangle's longest edge (a round surface of radius no less than half the edge bulges by
  /// at most a quarter of it), which is added to the margin there.
  double bulge_fraction = 0.25;
};
/// Its settings: names, units, ranges, help (sift_hull/settings.h).
template <>
const SettingTable<FreeSpaceConfig>& settingsOf<FreeSpaceConfig>();

/// Throws std::invalid_argument naming the first bad field.
void validate(const FreeSpaceConfig& config);

/// The finest voxels occupied in the hull (in cells: min_views; surface cells, which the
/// silhouettes settle within a voxel already: at least two) that at least min_views of the
/// points' views see in front of their surfaces (FreeSpaceConfig), in z, y, x order. The order of
/// the points does not matter. Throws std::invalid_argument for a point's view beyond `cameras`.
std::vector<Eigen::Vector3i> freeVoxels(const VisualHull& hull,
                                        const std::vector<PinholeCamera>& cameras,
                                        const std::vector<SurfacePoint>& points,
                                        const FreeSpaceConfig& config);

/// freeVoxels in slices of bounded time, so that a caller with other work (the hull node's
/// worker, whose views must not wait behind a refinement of seconds) can do it between them. The
/// views' surfaces are made one view per slice at most, then the hull's occupied leaves (as they
/// were at construction) are examined in runs sized to the time left. The union of what the
/// slices find equals freeVoxels(hull, ...) at construction, in no particular order.
///
/// Threads: one caller at a time; each slice runs on the hull's threads.
class FreeSpaceCarving {
 public:
  /// Takes the occupied leaves of `hull` as they are now; the hull is not read afterwards.
  /// Throws std::invalid_argument as freeVoxels does.
  FreeSpaceCarving(const VisualHull& hull, std::vector<PinholeCamera> cameras,
                   std::vector<SurfacePoint> points, const FreeSpaceConfig& config);
  ~FreeSpaceCarving();
  FreeSpaceCarving(const FreeSpaceCarving&) = delete;
  FreeSpaceCarving& operator=(const FreeSpaceCarving&) = delete;

  /// Works until `budget_s` of wall time is spent (at least one view's surface or one run of
  /// leaves; infinity: to the end), appending the free voxels found to `free`. True once done.
  bool step(double budget_s, std::vector<Eigen::Vector3i>* free);
  bool done() const;

 private:
  struct State;
  std::unique_ptr<State> state_;
};

}  // namespace sift_hull
