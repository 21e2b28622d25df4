#pragma once

#include <cstdint>
#include <functional>
#include <vector>

#include "sift_hull/hull/mesh.h"
#include "sift_hull/hull/octree.h"

namespace sift_hull {

/// Intersection over union of two masks (non-zero inside) of one size; 1 when both are empty.
double maskIoU(const cv::Mat& a, const cv::Mat& b);

/// IoU of the mesh's projection (rasteriseMask) with each view's silhouette.
struct ReprojectionIoU {
  std::vector<double> per_view;
  double min = 0.0, mean = 0.0;
  int sample_step_px = 1;  ///< the largest step between the pixels compared, in mask pixels
};
/// Each view at its mask's resolution (a reduced input's views at their reduction), on `threads`
/// threads. With `max_samples_per_view` > 0, a view of more pixels is compared at every k-th
/// pixel of every k-th row (pixel (k u, k v) of the mask against the mesh rasterised with pixel
/// centres there), k the smallest step that leaves at most that many: an unbiased sample of the
/// same IoU, for which a fine mesh's faces mostly hold no sample. `closed`: the mesh is
/// watertight (HullResult::mesh_check), and half its faces draw its projection (rasteriseMask).
ReprojectionIoU reprojectionIoU(const TriangleMesh& mesh, const std::vector<HullView>& views,
                                int threads = 1, size_t max_samples_per_view = 0,
                                bool closed = false);

/// Dense voxel carving, the brute-force reference: a voxel is occupied when every view keeps its
/// centre (HullView::keeps).
struct DenseGrid {
  Eigen::Vector3d origin_W = Eigen::Vector3d::Zero();
  double voxel_m = 1.0;
  int cells = 0;                  ///< per axis
  std::vector<uint8_t> occupied;  ///< x fastest, then y, then z

  Eigen::Vector3d centre(int i, int j, int k) const {
    return origin_W + (Eigen::Vector3d(i, j, k) + Eigen::Vector3d::Constant(0.5)) * voxel_m;
  }
  /// Position of voxel (i, j, k) in `occupied`.
  size_t index(int i, int j, int k) const {
    return (static_cast<size_t>(k) * cells + j) * cells + i;
  }
  size_t occupiedCount() const;
  /// Bounds of the occupied voxels (whole voxels); an empty box at the origin when none is.
  Box3d occupiedBounds() const;
};
DenseGrid denseCarving(const std::vector<HullView>& views, const Box3d& cube, int cells,
                       int threads);

/// Volume IoU of the hull with a dense grid, sampled at the grid's voxel centres. The hull holds a
/// point when its leaf is in, or is a surface cell and f_iso <= 0 at the point (the surface the
/// mesh follows), so that the octree's in and out decisions are what is compared.
double volumeIoU(const VisualHull& hull, const DenseGrid& dense);

/// Whether the hull holds a point, as volumeIoU decides it.
bool hullHolds(const VisualHull& hull, const Eigen::Vector3d& X_W);

/// The hull and a true solid sampled at one point in each of per_axis^3 cells over the hull's
/// cube (x fastest): the ground truth of free-space carving. The point's place in its cell comes
/// from a hash of the cell (stratified sampling, the same points on every call): at the cells'
/// centres, a face parallel to the grid falls at the same place in every cell, and the volumes of
/// the axis-aligned solids were off by up to a sample's width (the U-block's cut, 40 views:
/// 39.0 % with 200 samples per axis, 43.1 % with 160, 50.6 % with 256; stratified: 45.6-45.7 %
/// with any of them).
struct SolidSamples {
  int per_axis = 0;
  double cell_m3 = 0.0;
  std::vector<uint8_t> truth, hull;
  std::vector<uint8_t> cavity;  ///< in the solid's cavities (empty without `cavities`)
};
using SolidPredicate = std::function<bool(const Eigen::Vector3d& X_W)>;
/// `cavities`, when given, tells the space that a visual hull of the solid cannot remove (the
/// shape with its cuts filled, less the shape).
SolidSamples sampleAgainstSolid(const VisualHull& hull, const SolidPredicate& inside, int per_axis,
                                const SolidPredicate& cavities = {});

/// Volumes from the samples, cubic metres: the hull's, the solid's, the hull's beyond the solid
/// (what a visual hull cannot remove) and the solid's beyond the hull (wrongly carved).
struct SolidComparison {
  double iou = 0.0, hull_m3 = 0.0, truth_m3 = 0.0, excess_m3 = 0.0, missing_m3 = 0.0;
  double cavity_m3 = 0.0;         ///< the cavities' volume (within the cube)
  double cavity_filled_m3 = 0.0;  ///< the hull's volume in the cavities
};
SolidComparison compareWithSolid(const SolidSamples& samples);

/// The solid's volume held before and not after (of two samplings of one cube), over the solid's
/// volume: what refinement carved that it should not have. Throws std::invalid_argument for
/// samplings of different grids.
double falseCarvedFraction(const SolidSamples& before, const SolidSamples& after);

/// Mean distance of the mesh's vertices to a sphere's surface.
double meanDistanceToSphere(const TriangleMesh& mesh, const Eigen::Vector3d& centre_W,
                            double radius_m);

}  // namespace sift_hull
