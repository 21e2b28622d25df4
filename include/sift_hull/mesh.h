#pragma once

#include <Eigen/Core>
#include <functional>
#include <opencv2/core.hpp>
#include <string>
#include <vector>

#include "sift_hull/camera.h"

namespace sift_hull {

/// A triangle mesh in world coordinates; faces are counter-clockwise seen from outside, so their
/// normals (v1 - v0) x (v2 - v0) point out of the solid.
struct TriangleMesh {
  std::vector<Eigen::Vector3f> vertices_W;
  std::vector<Eigen::Vector3i> faces;
};

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

/// Topology of a mesh. Watertight: every edge has exactly two faces, which traverse it in opposite
/// directions, and no face is degenerate (repeated vertex index).
struct MeshCheck {
  bool watertight = false;
  size_t boundary_edges = 0;      ///< edges with one face
  size_t non_manifold_edges = 0;  ///< edges with three faces or more
  size_t misoriented_edges = 0;   ///< edges whose two faces traverse them the same way
  size_t degenerate_faces = 0;
};
MeshCheck checkMesh(const TriangleMesh& mesh);

/// Signed volume enclosed (positive for outward faces), in cubic world units.
double meshVolume(const TriangleMesh& mesh);

/// Binary little-endian PLY: float x y z per vertex, uchar-counted int list per face. Throws
/// std::runtime_error naming the path when it cannot be written / read or is not such a file.
void writePly(const std::string& path, const TriangleMesh& mesh);
TriangleMesh readPly(const std::string& path);

/// CV_8UC1 mask, 255 at every pixel whose centre the projection of a face covers (faces with a
/// vertex at non-positive depth are skipped).
cv::Mat rasteriseMask(const TriangleMesh& mesh, const PinholeCamera& camera, cv::Size size);

/// CV_8UC3 BGR image of the mesh from `camera`, z-buffered, each face grey-shaded by the angle
/// between its normal and the viewing ray; black background.
cv::Mat renderShaded(const TriangleMesh& mesh, const PinholeCamera& camera, cv::Size size);

/// `views` shaded renderings from cameras spaced around the mesh's bounding sphere (a ring at 25
/// deg elevation, looking at its centre), tiled in one image of tiles of `tile` size, two per row.
cv::Mat renderTurntable(const TriangleMesh& mesh, int views, cv::Size tile);

}  // namespace sift_hull
