#pragma once

#include <cstdint>
#include <functional>
#include <opencv2/core.hpp>
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

}  // namespace sift_hull
