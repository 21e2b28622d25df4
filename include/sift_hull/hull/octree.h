#pragma once

#include <Eigen/Core>
#include <cstdint>
#include <functional>
#include <memory>
#include <unordered_set>
#include <vector>

#include "sift_hull/hull/bounding_box.h"
#include "sift_hull/hull/hull_config.h"
#include "sift_hull/hull/hull_view.h"
#include "sift_hull/hull/marching_cubes.h"
#include "sift_hull/hull/mesh.h"

namespace sift_hull {

namespace detail {
struct OctreeNode;
}  // namespace detail

/// The octree's root cube: the box's longest edge plus at least one voxel on every side, its
/// corner on the voxel grid (integer multiples of the resolution), so that cells line up with an
/// OctoMap of the same resolution.
struct HullCube {
  Eigen::Vector3i origin_voxels = Eigen::Vector3i::Zero();  ///< corner / resolution
  double resolution_m = 1.0;                                ///< finest cell edge
  int depth = 1;

  /// 2^depth cells over the box's longest edge plus three cells. Throws std::invalid_argument
  /// for an empty or non-finite box, or one too far from the origin at that resolution.
  static HullCube around(const Box3d& box, int depth);
  /// Cells of exactly `resolution_m` (octomap_server's `resolution`), the least depth whose cube
  /// covers the box as `around` does; throws std::invalid_argument when that is deeper than
  /// limits::kMaxHullDepth, saying the least resolution that fits.
  static HullCube withResolution(const Box3d& box, double resolution_m);
  /// withResolution for config.resolution_m > 0, else around(box, config.max_depth).
  static HullCube forConfig(const Box3d& box, const HullConfig& config);
  Eigen::Vector3d origin_W() const { return origin_voxels.cast<double>() * resolution_m; }
  double edge_m() const { return resolution_m * (1 << depth); }
  Box3d box() const;
};

enum class CellState : uint8_t { kOut, kIn, kSurface };

/// A leaf of the octree: the cell at `depth` with integer index `index` (in cells of that depth)
/// spans cube.origin_W() + cell_edge * [index, index + 1].
struct HullCell {
  Eigen::Vector3i index = Eigen::Vector3i::Zero();
  int depth = 0;
  CellState state = CellState::kIn;
  /// For in and surface cells: the maximum of D_i at the centre over the views the cell applied
  /// (those its parent did not see all inside). It has the sign of f_iso (eq. 9) there, and its
  /// value where that is >= 0.
  float centre_value = 0.0f;
};

/// Leaf counts and memory of the octree.
struct HullStats {
  size_t in_leaves = 0, out_leaves = 0, surface_leaves = 0, nodes = 0;
  size_t bytes = 0;                 ///< octree nodes only
  double occupied_volume_m3 = 0.0;  ///< in cells plus finest surface cells with centre inside
};

/// The visual hull as an octree over a cube, classified with f_iso(v) = max_i D_i(P_i v) (eq. 9):
/// a cell is out when one view sees all of it outside its silhouette, in when every view sees all
/// of it inside, otherwise on the surface and split down to config.max_depth. Adding views refines
/// the existing tree and gives exactly the tree that adding them all at once gives.
class VisualHull {
 public:
  /// Throws std::invalid_argument for a bad config or an empty box.
  VisualHull(const Box3d& box, const HullConfig& config);
  ~VisualHull();
  VisualHull(VisualHull&&) noexcept;
  VisualHull& operator=(VisualHull&&) noexcept;
  VisualHull(const VisualHull&) = delete;
  VisualHull& operator=(const VisualHull&) = delete;
  /// A deep copy (the tree, the free voxels; the views' images are shared, never changed), for
  /// work on the hull as it is now while this one goes on carving.
  VisualHull clone() const;

  /// Carves with more views. Before any view the whole cube is one in cell. Throws
  /// std::invalid_argument, before carving with any of them, when a view's camera is too far
  /// from the cube for single precision (HullView::useFrame).
  void addViews(std::vector<HullView> views);
  void addView(HullView view);
  /// Throws std::invalid_argument when the view cannot join this hull: its camera too far from
  /// the cube for single precision (HullView::useFrame), or within a voxel of the cube's centre
  /// (a box far too large for the cameras).
  void checkView(const HullView& view) const;
  /// Removes the view added last and carves again with the others: the tree the others give.
  void dropLastView();
  /// Whether nothing is occupied: no in cell and no surface cell whose centre is inside.
  bool isEmpty() const;
  /// Back to one in cell, no views and no free voxels.
  void reset();

  /// Free-space carving: finest voxels (indices in the cube, 0 .. 2^depth - 1 on each axis; others
  /// are ignored) known to be empty, from lines of sight to surface points (src/core/refine).
  /// They become out, and so does every voxel all of whose corners touch free voxels; the in
  /// voxels next to them become finest surface cells, so that the mesh closes around the cavity
  /// (mesh() polygonises f = max(f_iso, f_free), f_free > 0 at the corners of free voxels: the
  /// mesh's cavity is the free voxels grown by a quarter of a voxel). The
  /// result depends only on the views and the union of the voxels given, not on the order of the
  /// calls: views added later carve the tree as they would have without free voxels.
  void carveFree(const std::vector<Eigen::Vector3i>& voxels);
  /// The free voxels so far (those given and those the closure added), in no particular order.
  std::vector<Eigen::Vector3i> freeVoxels() const;
  size_t freeVoxelCount() const { return free_.size(); }
  /// The finest surface cells beside free voxels where mesh()'s field, max(f_iso, f_free), is
  /// positive at all eight corners: marching cubes leaves them without surface, and the maps
  /// (occupiedBlocks, toOctomap, compactOctomap) call them free as the mesh does. Empty without
  /// free voxels. Cost: the surface cells' 26 neighbours looked up, f_iso at the open corners of
  /// those beside free voxels.
  std::vector<Eigen::Vector3i> hollowVoxels() const;

  const HullCube& cube() const { return cube_; }
  const HullConfig& config() const { return config_; }
  const std::vector<HullView>& views() const { return views_; }

  void forEachLeaf(const std::function<void(const HullCell&)>& visit) const;
  HullStats stats() const;
  /// The leaf holding a world point (a point outside the cube is out).
  HullCell leafAt(const Eigen::Vector3d& X_W) const;
  /// f_iso at a world point over all views (-kFarOutside_px without views): the silhouettes'
  /// field, free voxels aside.
  float valueAt(const Eigen::Vector3d& X_W) const;
  /// f_iso at many points, on config.threads threads.
  void sampleField(const std::vector<Eigen::Vector3d>& points_W, std::vector<float>* values) const;

  /// The tree's root, for the walks of src/core/hull (compactOctomap).
  const detail::OctreeNode& rootNode() const { return *root_; }

  /// The finest surface cells, for marching cubes.
  SurfaceCells surfaceCells() const;
  /// Marching cubes on f_iso over the surface cells.
  TriangleMesh mesh() const;

 private:
  struct CloneTag {};
  VisualHull(const VisualHull& other, CloneTag);

  HullCube cube_;
  HullConfig config_;
  /// The views' local frame (HullView::useFrame): the cube's centre, half its edge.
  Eigen::Vector3d frame_origin_W_;
  double frame_scale_;
  std::vector<HullView> views_;
  std::unique_ptr<detail::OctreeNode> root_;
  std::unordered_set<uint64_t> free_;  ///< packed finest voxel indices (free_carving.cpp)

  void applyFree(const std::vector<Eigen::Vector3i>& voxels);
  /// f_free's part in mesh(): raises `values` at the corners of free voxels.
  void addFreeField(const std::vector<Eigen::Vector3d>& points_W, std::vector<float>* values) const;
};

/// Occupied cells for maps: in cells of any size and surface cells at the finest level (but
/// VisualHull::hollowVoxels), each as
/// (min corner in voxels relative to the world origin, edge in voxels).
struct VoxelBlock {
  Eigen::Vector3i min_voxels;
  int edge_voxels;
};
std::vector<VoxelBlock> occupiedBlocks(const VisualHull& hull);
/// Every leaf as a block: occupied (occupiedBlocks') or carved (out cells of any size and the
/// finest cells of VisualHull::hollowVoxels).
void leafBlocks(const VisualHull& hull, std::vector<VoxelBlock>* occupied,
                std::vector<VoxelBlock>* carved);

/// The finest voxels (indices in the cube, as carveFree takes them) of the in and surface leaves
/// that a world box touches. Throws std::invalid_argument, before listing them, when there are
/// more than max_voxels.
std::vector<Eigen::Vector3i> occupiedVoxelsIn(const VisualHull& hull, const Box3d& box_W,
                                              size_t max_voxels);

}  // namespace sift_hull
