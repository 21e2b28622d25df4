#include <algorithm>
#include <atomic>
#include <cmath>
#include <iomanip>
#include <limits>
#include <opencv2/imgproc.hpp>
#include <sstream>
#include <stdexcept>
#include <thread>

#include "hull/distance_kernel.h"
#include "common/parallel.h"
#include "sift_hull/limits.h"
#include "sift_hull/hull/hull_view.h"
#include "sift_hull/hull/octree.h"

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

double spectralNorm2x2(const Eigen::Matrix3d& K) {
  return Eigen::JacobiSVD<Eigen::Matrix2d>(K.topLeftCorner<2, 2>()).singularValues()(0);
}

std::string shortNumber(double value) {
  std::ostringstream out;
  out << std::setprecision(3) << value;
  return out.str();
}

/// Whether a pixel (u, v) satisfies the bounds, open sides unbounded.
bool withinBounds(const SilhouetteBounds& bounds, double u, double v) {
  return !bounds.empty && (!bounds.has_u_min || u >= bounds.u_min_px) &&
         (!bounds.has_u_max || u <= bounds.u_max_px) &&
         (!bounds.has_v_min || v >= bounds.v_min_px) && (!bounds.has_v_max || v <= bounds.v_max_px);
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

float SignedDistanceMap::at(double u_px, double v_px) const {
  return detail::lookUp(distance_px_.ptr<float>(), distance_px_.cols,
                        detail::lookUpLimit(distance_px_.cols),
                        detail::lookUpLimit(distance_px_.rows),
                        static_cast<float>(u_px - origin_.x), static_cast<float>(v_px - origin_.y));
}

void validate(const HullConfig& config) {
  limits::requireInRange("HullConfig::max_depth", config.max_depth, 2, limits::kMaxHullDepth);
  if (!(config.distance_slack_px >= 0.0) || !std::isfinite(config.distance_slack_px)) {
    throw std::invalid_argument("HullConfig::distance_slack_px must be finite and >= 0");
  }
  limits::requireInRange("HullConfig::padding_px", config.padding_px, 1, limits::kMaxPaddingPx);
  limits::requireInRange("HullConfig::threads", config.threads, 1, limits::kMaxThreads);
}

HullView::HullView(std::string name, const PinholeCamera& camera, const cv::Mat& mask,
                   const HullConfig& config)
    : name_(std::move(name)),
      camera_(camera),
      mask_((checkMask(mask), mask.clone())),
      bounds_(silhouetteBounds(mask, config.carve_outside_image)),
      distance_(mask, bounds_, config.padding_px),
      carves_behind_(bounds_.empty || bounds_.boundedSides() > 0),
      kernel_(std::make_unique<detail::DistanceKernel>(makeKernel(config))) {}

HullView::HullView(const HullView& other)
    : name_(other.name_),
      camera_(other.camera_),
      mask_(other.mask_),
      bounds_(other.bounds_),
      distance_(other.distance_),
      carves_behind_(other.carves_behind_),
      frame_origin_W_(other.frame_origin_W_),
      frame_scale_(other.frame_scale_),
      kernel_(other.kernel_ ? std::make_unique<detail::DistanceKernel>(*other.kernel_) : nullptr) {}

HullView& HullView::operator=(const HullView& other) {
  if (this != &other) *this = HullView(other);
  return *this;
}

HullView::HullView(HullView&& other) noexcept = default;
HullView& HullView::operator=(HullView&& other) noexcept = default;
HullView::~HullView() = default;

detail::DistanceKernel HullView::makeKernel(const HullConfig& config) const {
  detail::DistanceKernel kernel{};
  const Eigen::Matrix3d& R = camera_.R();
  for (int i = 0; i < 9; ++i) kernel.R[i] = static_cast<float>(R(i / 3, i % 3));
  for (int i = 0; i < 3; ++i) kernel.t[i] = static_cast<float>(camera_.t()(i));
  const Eigen::Matrix3d& K = camera_.K();
  kernel.fx = K(0, 0), kernel.skew = K(0, 1), kernel.cx = K(0, 2);
  kernel.fy = K(1, 1), kernel.cy = K(1, 2);
  kernel.k_norm = static_cast<float>(spectralNorm2x2(K));
  kernel.slack_px = static_cast<float>(config.distance_slack_px);
  kernel.behind_value = carves_behind_ ? kFarOutside_px : -kFarOutside_px;
  const cv::Mat& map = distance_.map();
  kernel.map = map.ptr<float>();
  kernel.stride = map.cols;
  kernel.offset_u = static_cast<float>(-distance_.origin().x);
  kernel.offset_v = static_cast<float>(-distance_.origin().y);
  kernel.u_high = detail::lookUpLimit(map.cols), kernel.v_high = detail::lookUpLimit(map.rows);
  return kernel;
}

void HullView::useFrame(const Eigen::Vector3d& origin_W, double scale) {
  if (!origin_W.allFinite() || !(scale > 0.0) || !std::isfinite(scale)) {
    throw std::invalid_argument("view '" + name_ +
                                "': the hull's frame is not finite and positive");
  }
  const double distance = (camera_.centre() - origin_W).norm() / scale;
  if (!(distance <= kMaxCameraDistance)) {
    throw std::invalid_argument("view '" + name_ + "': its camera lies " + shortNumber(distance) +
                                " half cube edges from the hull's centre, more than " +
                                shortNumber(kMaxCameraDistance) +
                                ": it would see the hull as a point; check the calibration and "
                                "the box");
  }
  const Eigen::Vector3d t_local = (camera_.R() * origin_W + camera_.t()) / scale;
  for (int i = 0; i < 3; ++i) kernel_->t[i] = static_cast<float>(t_local(i));
  frame_origin_W_ = origin_W;
  frame_scale_ = scale;
}

float HullView::valueAt(const Eigen::Vector3d& X_W) const {
  const Eigen::Vector3d X_local = (X_W - frame_origin_W_) / frame_scale_;
  const float x = static_cast<float>(X_local.x()), y = static_cast<float>(X_local.y()),
              z = static_cast<float>(X_local.z());
  float value = -std::numeric_limits<float>::infinity();
  maxInto({&x, &y, &z, 1}, &value);
  return value;
}

Eigen::Vector2d HullView::pixelOf(const Eigen::Vector3d& X_C) const {
  const Eigen::Matrix3d& K = camera_.K();
  const double inverse_depth = 1.0 / X_C.z();
  const double x = X_C.x() * inverse_depth, y = X_C.y() * inverse_depth;
  return {K(0, 0) * x + K(0, 1) * y + K(0, 2), K(1, 1) * y + K(1, 2)};
}

bool HullView::keeps(const Eigen::Vector3d& X_W) const {
  const Eigen::Vector3d X_C = camera_.toCamera(X_W);
  if (!(X_C.z() > 0.0)) return !carves_behind_;
  const Eigen::Vector2d pixel = pixelOf(X_C);
  const long u = std::lround(pixel.x()), v = std::lround(pixel.y());
  if (u < 0 || v < 0 || u >= mask_.cols || v >= mask_.rows) {
    return withinBounds(bounds_, pixel.x(), pixel.y());
  }
  return mask_.at<uint8_t>(static_cast<int>(v), static_cast<int>(u)) != 0;
}

void HullView::maxInto(const PointBatch& points, float* values) const {
  detail::maxDistances(*kernel_, points, values);
}

void HullView::classifyBalls(const PointBatch& centres, float radius_m, float* values,
                             uint32_t* out_bits, uint32_t* in_bits) const {
  if (centres.count > 32) throw std::invalid_argument("classifyBalls: more than 32 centres");
  detail::classifyBalls(*kernel_, centres, radius_m, values, out_bits, in_bits);
}

std::vector<HullView> makeHullViews(const std::vector<std::string>& names,
                                    const std::vector<PinholeCamera>& cameras,
                                    const std::vector<cv::Mat>& masks, const HullConfig& config) {
  if (names.size() != cameras.size() || masks.size() != cameras.size()) {
    throw std::invalid_argument("makeHullViews: names, cameras and masks differ in count");
  }
  std::vector<std::unique_ptr<HullView>> made(cameras.size());
  detail::parallelFor(made.size(), config.threads, [&](size_t i) {
    made[i] = std::make_unique<HullView>(names[i], cameras[i], masks[i], config);
  });
  std::vector<HullView> views;
  for (auto& view : made) views.push_back(std::move(*view));
  return views;
}

HullCube HullCube::around(const Box3d& box, int depth) {
  const double longest_m = box.size().maxCoeff();
  if (!(longest_m > 0.0) || !std::isfinite(longest_m)) {
    throw std::invalid_argument("hull box must have a positive, finite size");
  }
  HullCube cube;
  cube.depth = depth;
  // 2^depth voxels = longest edge + 3: snapping the corner down costs up to one voxel, and at
  // least one voxel of margin remains on every side.
  cube.resolution_m = longest_m / ((1 << depth) - 3);
  const Eigen::Vector3d corner = box.min_W / cube.resolution_m - Eigen::Vector3d::Ones();
  // Voxel indices of the cube's cells must fit an int (and its far corner too).
  constexpr double kMaxVoxelIndex = 1 << 30;
  if (!(corner.cwiseAbs().maxCoeff() < kMaxVoxelIndex) || !box.min_W.allFinite()) {
    throw std::invalid_argument(
        "the hull box lies more than 2^30 voxels from the world origin at this resolution: "
        "express the poses in a frame nearer the object, or lower the depth");
  }
  cube.origin_voxels = corner.array().floor().cast<int>();
  return cube;
}

Box3d HullCube::box() const {
  Box3d result;
  result.min_W = origin_W();
  result.max_W = result.min_W + Eigen::Vector3d::Constant(edge_m());
  return result;
}

}  // namespace sift_hull
