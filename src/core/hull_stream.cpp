#include "sift_hull/hull_stream.h"

#include <algorithm>

#include "sift_hull/hull_pipeline.h"

namespace sift_hull {

HullStream::HullStream(HullStreamConfig config) : config_(std::move(config)) {
  validate(config_.hull);
}

HullStream::Outcome HullStream::add(const std::string& name, const PinholeCamera& camera,
                                    const cv::Mat& mask) {
  const auto& skip = config_.skip_views;
  if (std::find(skip.begin(), skip.end(), name) != skip.end()) return Outcome::kSkipped;
  HullView view(name, camera, mask, config_.hull);
  if (hull_) {
    hull_->addView(std::move(view));
    return Outcome::kCarved;
  }
  waiting_.push_back(std::move(view));
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
  waiting_.clear();
  hull_.reset();
  why_no_box_ = "no view yet";
}

}  // namespace sift_hull
