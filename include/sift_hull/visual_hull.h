#pragma once

#include <Eigen/Core>
#include <cstdint>
#include <functional>
#include <memory>
#include <opencv2/core.hpp>
#include <string>
#include <vector>

#include "sift_hull/bounding_box.h"
#include "sift_hull/camera.h"
#include "sift_hull/mesh.h"

namespace sift_hull {

namespace detail {
struct HullNode;
/// Everything a view's batched look-ups read, as floats.
struct DistanceKernel {
  float R[9], t[3];
  float fx, skew, cx, fy, cy;  ///< K
  float k_norm;                ///< spectral norm of K's upper-left 2x2
  float slack_px;
  float behind_value;  ///< valueAt of a point not in front of the camera
  const float* map;    ///< padded distance map, row-major
  int stride;
  float offset_u, offset_v;  ///< map column / row = pixel u / v + offset
  float u_high, v_high;      ///< look-ups clamp to [0, u_high] x [0, v_high]
};
}  // namespace detail

/// Signed distance transform of a silhouette in pixels: negative inside, positive outside, zero
/// on the boundary between inside and outside pixel squares (OpenCV's exact Euclidean
/// distanceTransform of the mask and of its complement). The image is padded with `padding_px`
/// pixels; a padding pixel counts as inside when it lies within the silhouette's bounds, whose
/// sides are open where the image border cuts the silhouette. So a view does not carve beyond a
/// side of its image where the object may go on, exactly as the bounding-box LP assumes.
///
/// The map covers only the inside pixels' bounding box plus `padding_px` on every side (within
/// the padded image): exact there. Look-ups elsewhere are clamped to the map, which gives a
/// lower bound of the distance (the map is convex and holds every inside pixel): safe for
/// carving, and positive, as those points are outside.
class SignedDistanceMap {
 public:
  SignedDistanceMap() = default;
  /// `mask`: CV_8UC1, non-zero inside; `bounds`: silhouetteBounds() of the mask. Throws
  /// std::invalid_argument for another type or an empty mask.
  SignedDistanceMap(const cv::Mat& mask, const SilhouetteBounds& bounds, int padding_px);

  /// Bilinear look-up at pixel coordinates (pixel centres at integers), clamped to the map.
  float at(double u_px, double v_px) const;
  cv::Size imageSize() const { return image_size_; }
  /// The map (CV_32FC1, continuous, at least 2x2) and the image pixel of its first element.
  const cv::Mat& map() const { return distance_px_; }
  cv::Point origin() const { return origin_; }

 private:
  cv::Mat distance_px_;  ///< CV_32FC1
  cv::Size image_size_;
  cv::Point origin_;  ///< image pixel of map element (0, 0)
};

/// Octree carving settings.
struct HullConfig {
  /// Octree levels below the root cube; resolution = cube edge / 2^max_depth.
  int max_depth = 8;
  /// Whether a view carves what it sees outside its image. When false, a view keeps the points
  /// seen beyond a side of its image where the border cuts its silhouette (the object may go on
  /// there), and carves the rest; see SignedDistanceMap.
  bool carve_outside_image = false;
  /// Added to a cell's projected radius before comparing with the signed distance: covers the error
  /// of the pixel-sampled, interpolated transform.
  double distance_slack_px = 1.0;
  int padding_px = 16;  ///< around each distance map (see SignedDistanceMap)
  int threads = 2;      ///< for carving and for the mesh's field samples
};

/// Throws std::invalid_argument naming the first bad field.
void validate(const HullConfig& config);

/// Where a view puts a cell or point.
enum class Verdict : uint8_t { kOut, kIn, kUndecided };

/// Points in structure-of-arrays form, for batched look-ups: coordinates as floats in the view's
/// local frame (HullView::useFrame), X_local = (X_W - origin_W) / scale.
struct PointBatch {
  const float* x;
  const float* y;
  const float* z;
  size_t count;
};

/// One calibrated silhouette, ready for carving.
class HullView {
 public:
  /// Throws std::invalid_argument for a mask that is not a non-empty CV_8UC1.
  HullView(std::string name, const PinholeCamera& camera, const cv::Mat& mask,
           const HullConfig& config);

  const std::string& name() const { return name_; }
  const PinholeCamera& camera() const { return camera_; }
  const cv::Mat& mask() const { return mask_; }
  /// The silhouette's 2-D bounds; open sides where the border cuts it, unless carving outside.
  const SilhouetteBounds& bounds() const { return bounds_; }
  cv::Size imageSize() const { return mask_.size(); }

  /// D_i(P_i X) of the paper's eq. 9 in pixels. A point not in front of the camera gets
  /// kFarOutside_px when the view has a bounded side (the LP's depth row), else -kFarOutside_px.
  float valueAt(const Eigen::Vector3d& X_W) const;
  /// The brute-force test of dense carving: whether the view keeps a point, by the mask pixel
  /// nearest to its projection, or by the bounds outside the image.
  bool keeps(const Eigen::Vector3d& X_W) const;
  /// values[i] = max(values[i], D_i(P_i X_i)) for a batch of points in the local frame: f_iso
  /// built view by view.
  void maxInto(const PointBatch& points, float* values) const;
  /// For balls of one radius (local units) around up to 32 centres (local frame), from the distance
  /// at each centre and the ball's projected radius (plus the slack): maxInto for the centres; bit
  /// i of `out_bits` set when the view sees all of ball i outside the silhouette, of `in_bits` when
  /// all inside.
  void classifyBalls(const PointBatch& centres, float radius_m, float* values, uint32_t* out_bits,
                     uint32_t* in_bits) const;

  static constexpr float kFarOutside_px = 1e6f;

  /// The frame of the batched look-ups: X_local = (X_W - origin_W) / scale. Single-precision
  /// arithmetic keeps its relative precision in a frame around the hull whatever the world
  /// coordinates are (a map frame far from its origin, millimetres or kilometres). Projection is
  /// invariant to the scale, so only the camera's translation changes: (R origin_W + t) / scale.
  /// Throws std::invalid_argument when the camera lies more than kMaxCameraDistance local units
  /// from the origin (it would see the frame's unit cube as less than a millionth of its focal
  /// length) or the frame is not finite and positive. The default frame is the world's.
  void useFrame(const Eigen::Vector3d& origin_W, double scale);
  static constexpr double kMaxCameraDistance = 1e6;

 private:
  /// Pixel of a point in the camera frame (K's last row is 0 0 1).
  Eigen::Vector2d pixelOf(const Eigen::Vector3d& X_C) const;

  detail::DistanceKernel makeKernel(const HullConfig& config) const;

  std::string name_;
  PinholeCamera camera_;
  cv::Mat mask_;
  SilhouetteBounds bounds_;
  SignedDistanceMap distance_;
  bool carves_behind_ = true;
  Eigen::Vector3d frame_origin_W_ = Eigen::Vector3d::Zero();
  double frame_scale_ = 1.0;
  detail::DistanceKernel kernel_;
};

/// Prepares views (their distance transforms) on `config.threads` threads. Names, cameras and
/// masks have one entry per view.
std::vector<HullView> makeHullViews(const std::vector<std::string>& names,
                                    const std::vector<PinholeCamera>& cameras,
                                    const std::vector<cv::Mat>& masks, const HullConfig& config);

/// The octree's root cube: the box's longest edge plus at least one voxel on every side, its
/// corner on the voxel grid (integer multiples of the resolution), so that cells line up with an
/// OctoMap of the same resolution.
struct HullCube {
  Eigen::Vector3i origin_voxels = Eigen::Vector3i::Zero();  ///< corner / resolution
  double resolution_m = 1.0;                                ///< finest cell edge
  int depth = 1;

  static HullCube around(const Box3d& box, int depth);
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
  /// Back to one in cell and no views.
  void reset();

  const HullCube& cube() const { return cube_; }
  const HullConfig& config() const { return config_; }
  const std::vector<HullView>& views() const { return views_; }

  void forEachLeaf(const std::function<void(const HullCell&)>& visit) const;
  HullStats stats() const;
  /// The leaf holding a world point (a point outside the cube is out).
  HullCell leafAt(const Eigen::Vector3d& X_W) const;
  /// f_iso at a world point over all views (-kFarOutside_px without views).
  float valueAt(const Eigen::Vector3d& X_W) const;
  /// f_iso at many points, on config.threads threads.
  void sampleField(const std::vector<Eigen::Vector3d>& points_W, std::vector<float>* values) const;

  /// The finest surface cells, for marching cubes.
  SurfaceCells surfaceCells() const;
  /// Marching cubes on f_iso over the surface cells.
  TriangleMesh mesh() const;

 private:
  HullCube cube_;
  HullConfig config_;
  /// The views' local frame (HullView::useFrame): the cube's centre, half its edge.
  Eigen::Vector3d frame_origin_W_;
  double frame_scale_;
  std::vector<HullView> views_;
  std::unique_ptr<detail::HullNode> root_;
};

/// Occupied cells for maps: in cells of any size and surface cells at the finest level, each as
/// (min corner in voxels relative to the world origin, edge in voxels).
struct VoxelBlock {
  Eigen::Vector3i min_voxels;
  int edge_voxels;
};
std::vector<VoxelBlock> occupiedBlocks(const VisualHull& hull);

}  // namespace sift_hull
