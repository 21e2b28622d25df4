#pragma once

#include <Eigen/Core>
#include <functional>
#include <vector>

#include "sift_hull/hull/mesh.h"

namespace sift_hull {

/// Cells of a regular grid to polygonise: cell (i, j, k) spans origin_W + cell_edge_m * [i, i+1] x
/// [j, j+1] x [k, k+1]; its corners are grid points with integer indices.
struct SurfaceCells {
  Eigen::Vector3d origin_W = Eigen::Vector3d::Zero();
  double cell_edge_m = 1.0;
  std::vector<Eigen::Vector3i> cells;  ///< min-corner indices, each listed once
};

/// Evaluates a scalar field (negative inside) at many world points: values->size() ==
/// points.size().
using FieldSampler =
    std::function<void(const std::vector<Eigen::Vector3d>& points_W, std::vector<float>* values)>;

/// Marching cubes over the given cells only (VTK's case table): evaluates the field once per
/// distinct corner, through calls of `field` on chunks of up to 65,536 points, puts a vertex where
/// the field crosses zero along a cell edge (linear interpolation), shares vertices between cells.
/// A closed surface results when every cell in which the field changes sign is listed. Works
/// through the cells in slabs of whole z layers, so that its working arrays stay small; takes the
/// cells by value to free them early.
TriangleMesh marchingCubes(SurfaceCells cells, const FieldSampler& field);

}  // namespace sift_hull
