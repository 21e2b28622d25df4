#pragma once

#include <Eigen/Core>
#include <opencv2/core.hpp>

namespace sift_hull {

/// Solid procedural texture: the albedo (BGR, each in [0, 1]) of a world point. It depends on the
/// point only, so a point looks the same from every view. Blobs with sharp edges at several scales
/// give SIFT plenty of keypoints.
cv::Vec3f solidTexture(const Eigen::Vector3d& X_W, unsigned seed);

}  // namespace sift_hull
