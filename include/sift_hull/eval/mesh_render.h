#pragma once

#include <opencv2/core.hpp>

#include "sift_hull/geometry/camera.h"
#include "sift_hull/hull/mesh.h"

namespace sift_hull {

/// CV_8UC1 mask, 255 at every pixel whose centre the projection of a face covers (faces with a
/// vertex at non-positive depth are skipped). `closed`: the mesh is watertight (checkMesh), so
/// every ray through its projection crosses it at least once each way, and the faces that turn
/// one way in the image (positive signed area) cover the projection alone: only they are drawn.
/// `faces_checked`: the caller has run requireValidFaces on the mesh (once for many views).
cv::Mat rasteriseMask(const TriangleMesh& mesh, const PinholeCamera& camera, cv::Size size,
                      bool closed = false, bool faces_checked = false);

/// CV_8UC3 BGR image of the mesh from `camera`, z-buffered, each face grey-shaded by the angle
/// between its normal and the viewing ray; black background.
cv::Mat renderShaded(const TriangleMesh& mesh, const PinholeCamera& camera, cv::Size size);

/// `views` shaded renderings from cameras spaced around the mesh's bounding sphere (a ring at 25
/// deg elevation, looking at its centre), tiled in one image of tiles of `tile` size, two per row.
cv::Mat renderTurntable(const TriangleMesh& mesh, int views, cv::Size tile);

}  // namespace sift_hull
