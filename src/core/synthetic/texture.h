#pragma once

#include <Eigen/Core>
#include <opencv2/core.hpp>

namespace sift_hull {

/// Solid procedural texture: the albedo (BGR, each in [0, 1]) of a world point. It depends on the
/// point only, so a point looks the same from every view. Blobs with sharp edges at several scales
/// give SIFT plenty of keypoints.
cv::Vec3f solidTexture(const Eigen::Vector3d& X_W, unsigned seed);

/// Albedo (BGR, [0, 1]) of the floor at world point (x, y): square tiles 0.5 m wide of a mottled
/// grey-brown, each a little lighter or darker, between dark joints. `footprint_m`, the size of a
/// pixel on the floor, fades the details smaller than it to their mean (no aliasing far away).
cv::Vec3f floorTexture(const Eigen::Vector2d& xy, double footprint_m, unsigned seed);

/// Albedo of a turntable's top face at `offset_xy` from its centre: a saturated blue, faintly
/// mottled, with a light ring near the rim (`radius_m`).
cv::Vec3f discTexture(const Eigen::Vector2d& offset_xy, double radius_m, unsigned seed);

}  // namespace sift_hull
