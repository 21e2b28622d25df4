#include "sift_hull/hull/distance_map.h"

#include <Eigen/LU>
#include <Eigen/SVD>
#include <algorithm>
#include <cmath>
#include <opencv2/imgproc.hpp>
#include <stdexcept>
#include <utility>

#include "hull/distance_kernel.h"

namespace sift_hull {
namespace {

void checkMask(const cv::Mat& mask) {
  if (mask.empty() || mask.type() != CV_8UC1) {
    throw std::invalid_argument("silhouette must be a non-empty CV_8UC1 mask");
  }
}

/// Distance of each pixel of `region` (non-zero) to the nearest pixel outside it; 0 outside.
cv::Mat distanceWithin(const cv::Mat& region) {
  cv::Mat distance;
  cv::distanceTransform(region, distance, cv::DIST_L2, cv::DIST_MASK_PRECISE, CV_32F);
  return distance;
}

/// The mask with a border of `padding` pixels, inside where withinBounds: the bounds' rectangle
/// (open sides reaching the map's edge) clipped to the map, then the mask over it.
cv::Mat paddedMask(const cv::Mat& mask, const SilhouetteBounds& bounds, int padding) {
  cv::Mat padded = cv::Mat::zeros(mask.rows + 2 * padding, mask.cols + 2 * padding, CV_8UC1);
  if (!bounds.empty) {
    // Pixel u lies within [u_min, u_max] exactly when ceil(u_min) <= u <= floor(u_max).
    const int first_col =
        bounds.has_u_min ? static_cast<int>(std::ceil(bounds.u_min_px)) + padding : 0;
    const int last_col = bounds.has_u_max ? static_cast<int>(std::floor(bounds.u_max_px)) + padding
                                          : padded.cols - 1;
    const int first_row =
        bounds.has_v_min ? static_cast<int>(std::ceil(bounds.v_min_px)) + padding : 0;
    const int last_row = bounds.has_v_max ? static_cast<int>(std::floor(bounds.v_max_px)) + padding
                                          : padded.rows - 1;
    const cv::Rect kept =
        cv::Rect(first_col, first_row, last_col - first_col + 1, last_row - first_row + 1) &
        cv::Rect(0, 0, padded.cols, padded.rows);
    padded(kept).setTo(255);
  }
  const cv::Mat inside = mask != 0;
  inside.copyTo(padded(cv::Rect(padding, padding, mask.cols, mask.rows)));
  return padded;
}

/// The inside pixels' bounding box grown by `margin` on every side, within the image; the whole
/// image when nothing is inside; at least 2x2 (for bilinear look-ups).
cv::Rect mapWindow(const cv::Mat& inside, int margin) {
  const cv::Rect image(0, 0, inside.cols, inside.rows);
  cv::Rect window = cv::boundingRect(inside);
  if (window.empty()) return image;
  window = cv::Rect(window.x - margin, window.y - margin, window.width + 2 * margin,
                    window.height + 2 * margin) &
           image;
  window.width = std::max(window.width, 2);
  window.height = std::max(window.height, 2);
  return window & image;
}

}  // namespace

SignedDistanceMap::SignedDistanceMap(const cv::Mat& mask, const SilhouetteBounds& bounds,
                                     int padding_px)
    : image_size_(mask.size()) {
  checkMask(mask);
  const cv::Mat padded = paddedMask(mask, bounds, padding_px);
  const cv::Rect window = mapWindow(padded, padding_px);
  origin_ = window.tl() - cv::Point(padding_px, padding_px);
  const cv::Mat inside = padded(window).clone();
  const cv::Mat to_inside = distanceWithin(inside == 0);
  distance_px_ = distanceWithin(inside);
  // Pixel distances are between centres; the boundary lies half a pixel from the last centre.
  for (int row = 0; row < inside.rows; ++row) {
    const uint8_t* is_inside = inside.ptr<uint8_t>(row);
    const float* outside_distance = to_inside.ptr<float>(row);
    float* distance = distance_px_.ptr<float>(row);
    for (int col = 0; col < inside.cols; ++col) {
      distance[col] = is_inside[col] ? 0.5f - distance[col] : outside_distance[col] - 0.5f;
    }
  }
}

SignedDistanceMap::SignedDistanceMap(cv::Mat distance_px, cv::Size image_size, cv::Point origin,
                                     int reduction, float error_px)
    : distance_px_(std::move(distance_px)),
      image_size_(image_size),
      origin_(origin),
      reduction_(reduction),
      error_px_(error_px) {
  if (distance_px_.type() != CV_32FC1 || distance_px_.rows < 2 || distance_px_.cols < 2 ||
      !distance_px_.isContinuous() || reduction < 1) {
    throw std::invalid_argument("SignedDistanceMap: not a continuous CV_32FC1 map of 2x2 or more");
  }
}

SignedDistanceMap SignedDistanceMap::undistorted(const PinholeCamera& camera) const {
  if (!camera.distorted()) return *this;
  // Element (c, r) of a map lies at image pixel origin + (c, r) * s + (s - 1) / 2, here and in
  // the result, whose pixels are ideal ones.
  const double s = reduction_, first_sample = 0.5 * (s - 1.0);
  const Eigen::Vector2d raw_min(origin_.x + first_sample, origin_.y + first_sample);
  const Eigen::Vector2d raw_max =
      raw_min + s * Eigen::Vector2d(distance_px_.cols - 1, distance_px_.rows - 1);
  const auto [low, high] = camera.undistortedBounds(raw_min, raw_max);
  const cv::Point first(static_cast<int>(std::floor(low.x() - first_sample - s)),
                        static_cast<int>(std::floor(low.y() - first_sample - s)));
  const double width = std::ceil((high.x() - first.x - first_sample) / s) + 2,
               height = std::ceil((high.y() - first.y - first_sample) / s) + 2;
  if (!(width * height <= 4.0 * distance_px_.total() + 1e4)) {
    throw std::invalid_argument(
        "the lens distortion maps the silhouette's window onto an ideal image more than four "
        "times its size: check the distortion coefficients");
  }
  SignedDistanceMap result;
  result.image_size_ = image_size_;
  result.origin_ = first;
  result.reduction_ = reduction_;
  result.error_px_ = error_px_;
  cv::Mat map_u(static_cast<int>(height), static_cast<int>(width), CV_32FC1);
  cv::Mat map_v(map_u.size(), CV_32FC1);
  const Eigen::Matrix3d& K = camera.K();
  const Eigen::Matrix3d K_inverse = K.inverse();
  const Eigen::Matrix2d K2 = K.topLeftCorner<2, 2>(), K2_inverse = K2.inverse();
  double lipschitz = 1.0;
  for (int row = 0; row < map_u.rows; ++row) {
    float* u = map_u.ptr<float>(row);
    float* v = map_v.ptr<float>(row);
    for (int col = 0; col < map_u.cols; ++col) {
      const Eigen::Vector2d ideal(first.x + first_sample + s * col,
                                  first.y + first_sample + s * row);
      const Eigen::Vector2d raw = camera.distortPixel(ideal);
      u[col] = static_cast<float>((raw.x() - origin_.x - first_sample) / s);
      v[col] = static_cast<float>((raw.y() - origin_.y - first_sample) / s);
      if (row % 4 == 0 && col % 4 == 0) {
        const Eigen::Vector2d normalised = (K_inverse * ideal.homogeneous()).hnormalized();
        const Eigen::Matrix2d J =
            K2 * distortionJacobian(camera.distortion(), normalised) * K2_inverse;
        lipschitz = std::max(lipschitz, Eigen::JacobiSVD<Eigen::Matrix2d>(J).singularValues()(0));
      }
    }
  }
  cv::remap(distance_px_, result.distance_px_, map_u, map_v, cv::INTER_LINEAR,
            cv::BORDER_REPLICATE);
  result.lipschitz_ = static_cast<float>(1.02 * lipschitz);
  return result;
}

float SignedDistanceMap::at(double u_px, double v_px) const {
  // Map coordinates of an image pixel: (u - first sample's u) / reduction.
  const double first_sample = 0.5 * (reduction_ - 1);
  return detail::lookUp(distance_px_.ptr<float>(), distance_px_.cols,
                        detail::lookUpLimit(distance_px_.cols),
                        detail::lookUpLimit(distance_px_.rows),
                        static_cast<float>((u_px - origin_.x - first_sample) / reduction_),
                        static_cast<float>((v_px - origin_.y - first_sample) / reduction_));
}

}  // namespace sift_hull
