#include "sift_hull/geometry/correspondence.h"

#include <algorithm>
#include <cmath>

namespace sift_hull {
namespace {

bool insideImage(const cv::Mat& image, const Eigen::Vector2d& pixel) {
  return pixel.x() > -0.5 && pixel.y() > -0.5 && pixel.x() < image.cols - 0.5 &&
         pixel.y() < image.rows - 0.5;
}

bool nearestDepth(const cv::Mat& depth, const Eigen::Vector2d& pixel, double* value) {
  *value = depth.at<float>(static_cast<int>(std::lround(pixel.y())),
                           static_cast<int>(std::lround(pixel.x())));
  return std::isfinite(*value);
}

}  // namespace

bool sampleDepth(const cv::Mat& depth, const Eigen::Vector2d& pixel, double* value) {
  if (!insideImage(depth, pixel)) return false;
  if (depth.cols < 2 || depth.rows < 2) return nearestDepth(depth, pixel, value);
  const int u0 = std::clamp(static_cast<int>(std::floor(pixel.x())), 0, depth.cols - 2);
  const int v0 = std::clamp(static_cast<int>(std::floor(pixel.y())), 0, depth.rows - 2);
  const double a = depth.at<float>(v0, u0), b = depth.at<float>(v0, u0 + 1);
  const double c = depth.at<float>(v0 + 1, u0), d = depth.at<float>(v0 + 1, u0 + 1);
  const double lo = std::min({a, b, c, d}), hi = std::max({a, b, c, d});
  if (std::isfinite(hi) && hi - lo < 0.01 * lo) {
    const double s = std::clamp(pixel.x() - u0, 0.0, 1.0), t = std::clamp(pixel.y() - v0, 0.0, 1.0);
    *value = (1 - t) * ((1 - s) * a + s * b) + t * ((1 - s) * c + s * d);
    return true;
  }
  return nearestDepth(depth, pixel, value);
}

TrueCorrespondence trueCorrespondence(const DepthView& a, const DepthView& b,
                                      const Eigen::Vector2d& pixel_a,
                                      double relative_depth_tolerance) {
  TrueCorrespondence result;
  double depth_a;
  if (!sampleDepth(a.depth, pixel_a, &depth_a)) return result;
  result.X_W = a.camera.backProject(pixel_a, depth_a);
  const double depth_in_b = b.camera.depth(result.X_W);
  result.pixel_b = b.camera.project(result.X_W);
  if (depth_in_b <= 0.0 || !insideImage(b.depth, result.pixel_b)) {
    result.visibility = Visibility::kOutsideImage;
    return result;
  }
  double seen_depth;
  const bool seen = sampleDepth(b.depth, result.pixel_b, &seen_depth);
  const bool agrees =
      seen && std::abs(seen_depth - depth_in_b) <= relative_depth_tolerance * depth_in_b;
  result.visibility = agrees ? Visibility::kVisible : Visibility::kOccluded;
  return result;
}

}  // namespace sift_hull
