#pragma once
// The 3-D side of the "views" silhouettes (sift_hull/hull/view_silhouettes.h): a coarse hull
// carved from working-size masks with tolerance, its support cut, its projection back.

#include <Eigen/Core>
#include <opencv2/core.hpp>
#include <vector>

#include "sift_hull/geometry/camera.h"
#include "sift_hull/hull/bounding_box.h"

namespace sift_hull {
namespace view_prior {

/// Maps a raw full-size pixel to the working size (pixel centres on integers in both).
struct PixelScale {
  double sx = 1.0, sy = 1.0;
  Eigen::Vector2d operator()(const Eigen::Vector2d& full) const {
    return {(full.x() + 0.5) * sx - 0.5, (full.y() + 0.5) * sy - 0.5};
  }
};

/// A regular grid's kept cells: centres in world coordinates, all of edge `cell`.
struct CoarseHull {
  std::vector<Eigen::Vector3d> centres_W;
  double cell = 0.0;
};

/// The cells of a grid over `box` (`cells` along its longest side) whose centre projects inside
/// the mask in every view that sees it inside its image, but at most `tolerated` views, and that
/// at least two views see.
CoarseHull carve(const std::vector<cv::Mat>& masks, const std::vector<PinholeCamera>& cameras,
                 const PixelScale& scale, const Box3d& box, int cells, int tolerated);

/// Keeps the largest 26-connected part of the cells (specks a few views agree on by chance go).
void keepLargestPart(CoarseHull* hull);

/// The box of the cells, grown by `margin_cells` cells.
Box3d boxOf(const CoarseHull& hull, double margin_cells);

/// The cameras' mean up direction (the negated image y axis, in world coordinates), unit length.
Eigen::Vector3d meanUp(const std::vector<PinholeCamera>& cameras);

/// Cuts a support from the bottom of the hull along `up` (a floor patch, a shadow, a turntable
/// disc) with what it hides below it from cameras above: the widest layer of the lower half and
/// the layers above it still 0.8 as wide (at most a tenth of the hull's height), when a third of the
/// top one's cells, and 1 % of the hull's, lie outside the footprint of the five layers above it
/// grown by two cells; everything up to that top goes. Returns the share of cells removed;
/// `height` gets the cut's height above the lowest cell.
double cutSupport(const Eigen::Vector3d& up, CoarseHull* hull, double* height);

/// The hull's projection into a view of `size` (working pixels): its surface cells splatted as
/// discs of the cell's projected size, closed.
cv::Mat project(const CoarseHull& hull, const PinholeCamera& camera, const PixelScale& scale,
                cv::Size size);

}  // namespace view_prior
}  // namespace sift_hull
