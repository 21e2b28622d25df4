#pragma once

#include <octomap/ColorOcTree.h>
#include <octomap/OcTree.h>

#include <cstdint>
#include <functional>
#include <memory>
#include <opencv2/core.hpp>
#include <string>
#include <vector>

#include "sift_hull/geometry/camera.h"
#include "sift_hull/hull/mesh.h"

namespace sift_hull {

/// What colourMesh found.
struct MeshColouring {
  size_t coloured_vertices = 0;  ///< seen by at least one view
  size_t unseen_vertices = 0;    ///< seen by none: grey (128, 128, 128)
};

/// Colours each vertex of `mesh` (TriangleMesh::colours_rgb) by the median, per channel, of the
/// views that see it: the vertex faces the camera (its normal, the area-weighted mean of its
/// faces') and lies no farther than the mesh's own depth there (a z-buffer of its triangles at up
/// to 640 pixels across) plus twice the median edge. `image(i)` is view i's 8-bit grey, BGR or
/// BGRA image of the size its camera was calibrated for (asked for once, in order). Throws
/// std::invalid_argument for an image that is empty or of another type.
MeshColouring colourMesh(TriangleMesh* mesh, const std::vector<PinholeCamera>& cameras,
                         const std::function<cv::Mat(uint32_t)>& image, int threads);

/// A coloured mesh as `camera` sees it in an image of `size` (raw pixels): each pixel the colour
/// of the nearest triangle there, its vertices' colours interpolated.
struct MeshRendering {
  cv::Mat bgr;      ///< CV_8UC3, black where no triangle is
  cv::Mat covered;  ///< CV_8UC1, 255 where a triangle is
};
/// Throws std::invalid_argument for a mesh without one colour per vertex.
MeshRendering renderColouredMesh(const TriangleMesh& mesh, const PinholeCamera& camera,
                                 cv::Size size);

/// A rendering against a photograph inside a silhouette: the mean absolute error over the three
/// channels (grey levels) and the PSNR (dB, of the mean squared error); pixels the mesh does not
/// cover count as black. Throws std::invalid_argument for sizes that differ or an empty mask.
struct ColourError {
  double mae = 0.0, psnr_db = 0.0;
  size_t pixels = 0;
};
ColourError colourError(const MeshRendering& rendering, const cv::Mat& photo, const cv::Mat& mask);

/// `tree` as OctoMap's ColorOcTree (octovis and rviz's octomap plugin show its colours): the same
/// nodes and occupancy, each occupied leaf of the finest level coloured by the mean colour of the
/// coloured mesh's vertices in it, or when none lies in it, of those in the 26 voxels around it
/// (coarser occupied leaves, the inside, stay white; a pruned block of occupied voxels that holds a
/// vertex is expanded to the voxels that hold one, with its occupancy). Throws
/// std::invalid_argument for a mesh without one colour per vertex.
std::unique_ptr<octomap::ColorOcTree> colourOctomap(const octomap::OcTree& tree,
                                                    const TriangleMesh& mesh);

/// Writes OctoMap's .ot file of `tree` with its resolution exact to the double (OctoMap's own
/// write keeps the stream's six digits, which moves the voxel grid). Throws std::runtime_error
/// naming the path on failure.
void writeColourOctomap(const octomap::ColorOcTree& tree, const std::string& path);

}  // namespace sift_hull
