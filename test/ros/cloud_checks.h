#pragma once

// The nodes' triangulated clouds against the renderer's depth maps.

#include <sensor_msgs/PointCloud2.h>
#include <sensor_msgs/point_cloud2_iterator.h>

#include <cmath>
#include <cstddef>
#include <opencv2/core.hpp>

#include "sift_hull/geometry/camera.h"

namespace sift_hull {
namespace test {

/// A cloud's points, and how many lie where the depth map says.
struct DepthAgreement {
  size_t points = 0;
  size_t on_surface = 0;
};

/// The points of `cloud` (metres, in the frame of `camera`, which sees `depth`, CV_32FC1 depth in
/// metres) whose depth is within `tolerance` of their depth times the map's at the pixel they
/// project to; points projecting outside the map count as off the surface.
inline DepthAgreement depthAgreement(const sensor_msgs::PointCloud2& cloud,
                                     const PinholeCamera& camera, const cv::Mat& depth,
                                     double tolerance = 0.02) {
  DepthAgreement agreement;
  for (sensor_msgs::PointCloud2ConstIterator<float> p(cloud, "x"); p != p.end(); ++p) {
    const Eigen::Vector3d X(p[0], p[1], p[2]);
    const Eigen::Vector2d pixel = camera.project(X);
    const int u = static_cast<int>(std::lround(pixel.x())),
              v = static_cast<int>(std::lround(pixel.y()));
    ++agreement.points;
    if (u < 0 || v < 0 || u >= depth.cols || v >= depth.rows) continue;
    agreement.on_surface += std::abs(depth.at<float>(v, u) - X.z()) < tolerance * X.z();
  }
  return agreement;
}

}  // namespace test
}  // namespace sift_hull
