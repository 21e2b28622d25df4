#include "sift_hull/hull_stream.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>

#include "sift_hull/hull_pipeline.h"

namespace sift_hull {

void validate(const HullStreamConfig& config) {
  validate(config.hull);
  if (!(config.min_view_distance_m >= 0.0) || !std::isfinite(config.min_view_distance_m)) {
    throw std::invalid_argument("min_view_distance_m must be finite and at least 0");
  }
  if (!(config.min_view_angle_deg >= 0.0 && config.min_view_angle_deg <= 180.0)) {
    throw std::invalid_argument("min_view_angle_deg must lie in [0, 180]");
  }
}

HullStream::HullStream(HullStreamConfig config) : config_(std::move(config)) { validate(config_); }

bool HullStream::isRedundant(const PinholeCamera& camera) const {
  if (config_.min_view_distance_m <= 0.0) return false;
  // The tolerance keeps a camera standing still redundant at 0 degrees despite rounding.
  const double min_cos = std::cos(config_.min_view_angle_deg * M_PI / 180.0) - 1e-12;
  const Eigen::Vector3d centre = camera.centre();
  const Eigen::Vector3d axis = camera.opticalAxis();
  return std::any_of(taken_.begin(), taken_.end(), [&](const Viewpoint& taken) {
    return (taken.centre - centre).norm() <= config_.min_view_distance_m &&
           taken.axis.dot(axis) >= min_cos;
  });
}

HullStream::Outcome HullStream::add(const std::string& name, const PinholeCamera& camera,
                                    const cv::Mat& mask) {
  const auto& skip = config_.skip_views;
  if (std::find(skip.begin(), skip.end(), name) != skip.end()) return Outcome::kSkipped;
  if (isRedundant(camera)) {
    ++redundant_views_;
    return Outcome::kRedundant;
  }
  HullView view(name, camera, mask, config_.hull);
  const Viewpoint viewpoint{camera.centre(), camera.opticalAxis()};
  if (hull_) {
    hull_->addView(std::move(view));
    taken_.push_back(viewpoint);
    return Outcome::kCarved;
  }
  waiting_.push_back(std::move(view));
  taken_.push_back(viewpoint);
  tryToStart();
  return hull_ ? Outcome::kCarved : Outcome::kWaiting;
}

void HullStream::tryToStart() {
  std::optional<Box3d> box = config_.box;
  if (!box) {
    try {
      box = boundingBoxOf(waiting_);
    } catch (const HullBoxError& e) {
      // Fewer than two views, or cones still parallel: later views may bound the box.
      why_no_box_ = e.what();
      return;
    }
  }
  hull_ = std::make_unique<VisualHull>(*box, config_.hull);
  hull_->addViews(std::move(waiting_));
  waiting_.clear();
  why_no_box_.clear();
}

void HullStream::reset() {
  taken_.clear();
  redundant_views_ = 0;
  waiting_.clear();
  hull_.reset();
  why_no_box_ = "no view yet";
}

}  // namespace sift_hull
