#pragma once

#include <Eigen/Core>
#include <opencv2/core.hpp>

#include "sift_hull/geometry/camera.h"

namespace sift_hull {

/// A camera with its depth map (CV_32FC1, depth along the optical axis, +inf on the background).
struct DepthView {
  PinholeCamera camera;
  cv::Mat depth;
};

enum class Visibility {
  kVisible,       ///< the point is seen in view b at `pixel_b`
  kOccluded,      ///< it projects into view b, but something nearer is seen there
  kOutsideImage,  ///< it projects outside view b's image (or behind the camera)
  kBackground,    ///< the pixel of view a sees no object
};

struct TrueCorrespondence {
  Visibility visibility = Visibility::kBackground;
  Eigen::Vector2d pixel_b = Eigen::Vector2d::Zero();  ///< set unless kBackground
  Eigen::Vector3d X_W = Eigen::Vector3d::Zero();      ///< the scene point, set unless kBackground
};

/// Depth at a sub-pixel position: bilinear between the four nearest pixel centres where they all
/// see the same surface (spread under 1 %), else the nearest pixel's. False outside the image or on
/// the background.
bool sampleDepth(const cv::Mat& depth, const Eigen::Vector2d& pixel, double* value);

/// True position in view b of what pixel_a of view a sees. A point counts as visible in b when b's
/// depth there agrees with the point's depth within `relative_depth_tolerance`.
TrueCorrespondence trueCorrespondence(const DepthView& a, const DepthView& b,
                                      const Eigen::Vector2d& pixel_a,
                                      double relative_depth_tolerance = 0.01);

}  // namespace sift_hull
