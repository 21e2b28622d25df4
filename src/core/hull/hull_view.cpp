#include "sift_hull/hull/hull_view.h"

#include <algorithm>
#include <atomic>
#include <cmath>
#include <iomanip>
#include <limits>
#include <opencv2/imgproc.hpp>
#include <sstream>
#include <stdexcept>
#include <thread>

#include "common/parallel.h"
#include "hull/distance_kernel.h"
#include "sift_hull/hull/reduced_distance_map.h"
#include "sift_hull/limits.h"

namespace sift_hull {
namespace {

void checkMask(const cv::Mat& mask) {
  if (mask.empty() || mask.type() != CV_8UC1) {
    throw std::invalid_argument("silhouette must be a non-empty CV_8UC1 mask");
  }
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

/// Throws std::invalid_argument when the view's distortion cannot be inverted over its padded
/// image: the coefficients do not describe a lens for an image of this size.
void checkDistortion(const std::string& name, const PinholeCamera& camera, cv::Size size,
                     int padding_px) {
  requireUnfoldedDistortion(name, camera, size.width, size.height, padding_px);
}

/// The bounds of the undistorted silhouette, in ideal pixels: the extremes of its boundary pixels'
/// corners undistorted (the boundary maps onto the boundary); open sides as in `raw`.
SilhouetteBounds idealBounds(const SilhouetteBounds& raw, const PinholeCamera& camera,
                             const cv::Mat& mask) {
  if (raw.empty || !camera.distorted()) return raw;
  std::vector<std::vector<cv::Point>> contours;
  cv::findContours(mask != 0, contours, cv::RETR_EXTERNAL, cv::CHAIN_APPROX_NONE);
  Eigen::Vector2d low = Eigen::Vector2d::Constant(std::numeric_limits<double>::infinity());
  Eigen::Vector2d high = -low;
  for (const std::vector<cv::Point>& contour : contours) {
    for (const cv::Point& p : contour) {
      for (const Eigen::Vector2d& corner :
           {Eigen::Vector2d(p.x - 0.5, p.y - 0.5), Eigen::Vector2d(p.x + 0.5, p.y - 0.5),
            Eigen::Vector2d(p.x - 0.5, p.y + 0.5), Eigen::Vector2d(p.x + 0.5, p.y + 0.5)}) {
        const std::optional<Eigen::Vector2d> ideal = camera.undistortPixel(corner);
        if (!ideal) continue;  // checkDistortion has made sure the image undistorts
        low = low.cwiseMin(*ideal);
        high = high.cwiseMax(*ideal);
      }
    }
  }
  SilhouetteBounds bounds = raw;
  bounds.u_min_px = low.x(), bounds.v_min_px = low.y();
  bounds.u_max_px = high.x(), bounds.v_max_px = high.y();
  return bounds;
}

/// idealBounds of a run-length mask, decoded for the contours only when the camera is distorted.
SilhouetteBounds idealBounds(const SilhouetteBounds& raw, const PinholeCamera& camera,
                             const RunLengthMask& mask) {
  if (raw.empty || !camera.distorted()) return raw;
  return idealBounds(raw, camera, mask.decode());
}

}  // namespace

HullView::HullView(std::string name, const PinholeCamera& camera, const cv::Mat& mask,
                   const HullConfig& config)
    : name_(std::move(name)),
      camera_(camera),
      mask_((checkMask(mask), checkDistortion(name_, camera, mask.size(), config.padding_px),
             RunLengthMask(mask))),
      bounds_(idealBounds(silhouetteBounds(mask, config.carve_outside_image), camera, mask)),
      distance_(SignedDistanceMap(mask, silhouetteBounds(mask, config.carve_outside_image),
                                  config.padding_px)
                    .undistorted(camera)),
      carves_behind_(bounds_.empty || bounds_.boundedSides() > 0),
      kernel_(std::make_unique<detail::DistanceKernel>(makeKernel(config))) {}

HullView::HullView(std::string name, const PinholeCamera& camera, RunLengthMask mask,
                   const HullConfig& config, int distance_reduction)
    : name_(std::move(name)),
      camera_(camera),
      mask_(std::move(mask)),
      bounds_(viewBounds(name_, camera, mask_, config)),
      distance_(reducedSignedDistanceMap(mask_, silhouetteBounds(mask_, config.carve_outside_image),
                                         config.padding_px, distance_reduction)
                    .undistorted(camera)),
      carves_behind_(bounds_.empty || bounds_.boundedSides() > 0),
      kernel_(std::make_unique<detail::DistanceKernel>(makeKernel(config))) {}

SilhouetteBounds viewBounds(const std::string& name, const PinholeCamera& camera,
                            const RunLengthMask& mask, const HullConfig& config) {
  checkDistortion(name, camera, mask.size(), config.padding_px);
  return idealBounds(silhouetteBounds(mask, config.carve_outside_image), camera, mask);
}

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
  // Map column = (u - first sample's u) / reduction: K scaled by 1 / reduction, the first
  // sample's offset in offset_u / offset_v. The map's values and k_norm stay in image pixels.
  const Eigen::Matrix3d& K = camera_.K();
  const double reduction = distance_.reduction();
  kernel.fx = K(0, 0) / reduction, kernel.skew = K(0, 1) / reduction;
  kernel.cx = K(0, 2) / reduction;
  kernel.fy = K(1, 1) / reduction, kernel.cy = K(1, 2) / reduction;
  // The map's values change by up to lipschitz() raw pixels per ideal pixel (1 without distortion).
  kernel.k_norm = static_cast<float>(spectralNorm2x2(K)) * distance_.lipschitz();
  kernel.slack_px = static_cast<float>(config.distance_slack_px + distance_.errorBound_px()) *
                    distance_.lipschitz();
  kernel.behind_value = carves_behind_ ? kFarOutside_px : -kFarOutside_px;
  const cv::Mat& map = distance_.map();
  kernel.map = map.ptr<float>();
  kernel.stride = map.cols;
  const double first_sample = 0.5 * (reduction - 1);
  kernel.offset_u = static_cast<float>(-(distance_.origin().x + first_sample) / reduction);
  kernel.offset_v = static_cast<float>(-(distance_.origin().y + first_sample) / reduction);
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
  const Eigen::Vector2d raw = camera_.distortPixel(pixel);
  const long u = std::lround(raw.x()), v = std::lround(raw.y());
  if (u < 0 || v < 0 || u >= mask_.size().width || v >= mask_.size().height) {
    return withinBounds(bounds_, pixel.x(), pixel.y());
  }
  return mask_.at(static_cast<int>(u), static_cast<int>(v));
}

void HullView::maxInto(const PointBatch& points, float* values) const {
  detail::maxDistances(*kernel_, points, values);
}

void HullView::ballBound(float x, float y, float z, float radius, float* value,
                         float* reach) const {
  detail::ballBound(*kernel_, x, y, z, radius, value, reach);
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

}  // namespace sift_hull
