#include "sift_hull/hull/hull_stream.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>

#include "sift_hull/hull/hull_pipeline.h"
#include "sift_hull/hull/reduced_distance_map.h"

namespace sift_hull {
namespace {

/// Why a silhouette carves nothing useful: empty when it covers some but not all of its image.
std::string coverageProblem(const cv::Mat& mask) {
  if (mask.empty() || mask.type() != CV_8UC1) return "";  // HullView says what is wrong
  const int inside = cv::countNonZero(mask);
  if (inside == 0) return "its silhouette covers no pixel";
  if (static_cast<size_t>(inside) == mask.total()) {
    return "its silhouette covers the whole image (a threshold or mask problem?)";
  }
  return "";
}

/// Why a camera cannot take part in the box LP: empty when its projection is finite.
std::string cameraProblem(const PinholeCamera& camera) {
  if (camera.projectionMatrix().allFinite() && camera.centre().allFinite()) return "";
  return "its camera's projection is beyond double precision (a translation near 1e308?)";
}

}  // namespace


HullStream::HullStream(HullStreamConfig config) : config_(std::move(config)) { validate(config_); }

bool HullStream::isRedundant(const PinholeCamera& camera) const {
  if (config_.min_view_distance_m <= 0.0) return false;
  // The tolerance keeps a camera standing still redundant at 0 degrees despite rounding.
  const double min_cos = std::cos(config_.min_view_angle_deg * M_PI / 180.0) - 1e-12;
  const Eigen::Vector3d centre = camera.centre();
  const Eigen::Vector3d axis = camera.opticalAxis();
  const auto near = [&](const PinholeCamera& taken) {
    return (taken.centre() - centre).norm() <= config_.min_view_distance_m &&
           taken.opticalAxis().dot(axis) >= min_cos;
  };
  return std::any_of(waiting_.begin(), waiting_.end(),
                     [&](const Arrival& a) { return near(a.view.camera()); }) ||
         (hull_ && std::any_of(hull_->views().begin(), hull_->views().end(),
                               [&](const HullView& v) { return near(v.camera()); }));
}

void HullStream::refuse(const std::string& name, uint64_t serial, const std::string& reason) {
  ++refused_views_;
  // Reasons from VisualHull::checkView name the view already.
  const std::string prefix = "view '" + name + "': ";
  refusals_.push_back(reason.rfind(prefix, 0) == 0 ? reason : prefix + reason);
  if (serial == arrivals_) newest_refused_ = true;
}

std::vector<std::string> HullStream::takeRefusals() {
  std::vector<std::string> taken;
  taken.swap(refusals_);
  return taken;
}

HullStream::Outcome HullStream::add(const std::string& name, const PinholeCamera& camera,
                                    const cv::Mat& mask) {
  const auto& skip = config_.skip_views;
  if (std::find(skip.begin(), skip.end(), name) != skip.end()) return Outcome::kSkipped;
  const uint64_t serial = ++arrivals_;
  newest_refused_ = false;
  std::string coverage = coverageProblem(mask);
  if (coverage.empty()) coverage = cameraProblem(camera);
  if (coverage.empty() && config_.box && !(camera.depth(config_.box->centre()) > 0.0)) {
    coverage = "its camera sees the given box behind it (the box's centre has depth <= 0)";
  }
  const size_t views = waiting_.size() + (hull_ ? hull_->views().size() : 0);
  if (!coverage.empty()) {
    refuse(name, serial, coverage);
  } else if (views >= static_cast<size_t>(config_.max_views)) {
    refuse(name, serial,
           "the hull holds max_views (" + std::to_string(config_.max_views) + ") views already");
  } else if (isRedundant(camera)) {
    ++redundant_views_;
    return Outcome::kRedundant;
  } else {
    take({viewOf(name, camera, mask), serial});
  }
  if (newest_refused_) return Outcome::kRefused;
  return hull_ ? Outcome::kCarved : Outcome::kWaiting;
}

/// Once the hull has its box, a view's distance map is sampled at the reduction the box allows
/// (distanceReduction: full resolution below kMinReducedImagePixels), as the offline hull does; a
/// view waiting for the box keeps its full-resolution map.
HullView HullStream::viewOf(const std::string& name, const PinholeCamera& camera,
                            const cv::Mat& mask) const {
  if (!hull_) return HullView(name, camera, mask, config_.hull);
  const int reduction = distanceReduction(camera, mask.size(), box_, config_.hull);
  if (reduction == 1) return HullView(name, camera, mask, config_.hull);
  return HullView(name, camera, RunLengthMask(mask), config_.hull, reduction);
}

void HullStream::take(Arrival arrival) {
  if (hull_) return addToHull(std::move(arrival));
  wait(std::move(arrival));
}

void HullStream::wait(Arrival arrival) {
  if (waiting_.size() < static_cast<size_t>(config_.max_waiting_views)) {
    waiting_.push_back(std::move(arrival));
    return tryToStart();
  }
  const HullView& oldest = waiting_.front().view;
  refuse(oldest.name(), waiting_.front().serial,
         "no box after max_waiting_views (" + std::to_string(config_.max_waiting_views) +
             ") views: " + why_no_box_);
  std::vector<Arrival> rest(std::make_move_iterator(waiting_.begin() + 1),
                            std::make_move_iterator(waiting_.end()));
  rest.push_back(std::move(arrival));
  waiting_.clear();
  replay(std::move(rest));
}

void HullStream::replay(std::vector<Arrival> arrivals) {
  for (Arrival& arrival : arrivals) take(std::move(arrival));
}

void HullStream::addToHull(Arrival arrival) {
  const std::string name = arrival.view.name();
  try {
    hull_->checkView(arrival.view);
  } catch (const std::invalid_argument& e) {
    return refuse(name, arrival.serial, e.what());
  }
  hull_->addView(std::move(arrival.view));
  if (hull_->isEmpty()) {
    hull_->dropLastView();  // rare: a full re-carve beats copying the tree for every view
    return refuse(name, arrival.serial, "it would carve the hull to nothing");
  }
  refitBox();
}

/// The LP box of every view taken shrinks as views come (each adds constraints). When it lies
/// more than a cell (of its own cube) inside the hull's box on some face, the hull is carved again
/// in it, so that the box and the resolution are those `sift_hull hull` gives for the same views;
/// shrinking mostly happens while few views are in, when carving again is cheap. Never with a
/// given box.
void HullStream::refitBox() {
  if (config_.box) return;
  Box3d tighter;
  try {
    tighter = boundingBoxOf(hull_->views());
  } catch (const std::exception&) {
    return;  // the LP over the taken views failed: keep the box it had
  }
  std::unique_ptr<VisualHull> refitted;
  try {
    const double cell_m = HullCube::forConfig(tighter, config_.hull).resolution_m;
    if ((tighter.min_W - box_.min_W).maxCoeff() <= cell_m &&
        (box_.max_W - tighter.max_W).maxCoeff() <= cell_m) {
      return;
    }
    refitted = std::make_unique<VisualHull>(tighter, config_.hull);
    refitted->addViews(hull_->views());
  } catch (const std::exception&) {
    return;  // a box the views cannot join (too far, too fine a resolution): keep the one it had
  }
  if (refitted->isEmpty()) return;
  hull_ = std::move(refitted);
  ++hull_generation_;
  box_ = tighter;
  ++refits_;
}

void HullStream::tryToStart() {
  if (config_.box) return startHull(*config_.box);
  std::vector<HullView> views;
  for (const Arrival& arrival : waiting_) views.push_back(arrival.view);
  try {
    startHull(boundingBoxOf(views));
  } catch (const HullBoxError& e) {
    // Fewer than two views, or cones still parallel: later views may bound the box.
    why_no_box_ = e.what();
    if (e.reason() == HullBoxError::Reason::kEmpty) dropViewMissingTheOthers();
  } catch (const std::invalid_argument& e) {
    // A box the octree cannot hold (HullCube::around): the views go on waiting, within
    // max_waiting_views.
    hull_.reset();
    why_no_box_ = e.what();
  }
}

/// When the LP over the waiting views is empty, the view whose cone misses the others is the one
/// without which the rest are not empty, and it must be the only such view: with two views either
/// could be the bad one, so both wait for a third.
void HullStream::dropViewMissingTheOthers() {
  std::vector<size_t> culprits;
  for (size_t i = 0; i < waiting_.size(); ++i) {
    std::vector<HullView> others;
    for (size_t j = 0; j < waiting_.size(); ++j) {
      if (j != i) others.push_back(waiting_[j].view);
    }
    try {
      boundingBoxOf(others);
      culprits.push_back(i);
    } catch (const HullBoxError& e) {
      if (e.reason() != HullBoxError::Reason::kEmpty) culprits.push_back(i);
    }
  }
  if (culprits.size() != 1) return;
  const size_t bad = culprits.front();
  refuse(waiting_[bad].view.name(), waiting_[bad].serial,
         "its viewing cone misses the other views' cones");
  std::vector<Arrival> rest;
  for (size_t j = 0; j < waiting_.size(); ++j) {
    if (j != bad) rest.push_back(std::move(waiting_[j]));
  }
  waiting_.clear();
  replay(std::move(rest));
}

/// Starts the hull in `box` with the waiting views that can join it, all at once (carving them
/// one by one from the whole cube would refine a far larger tree on the way). Should they carve
/// it to nothing, they are added again one by one (addToHull) to refuse the ones that do.
void HullStream::startHull(const Box3d& box) {
  hull_ = std::make_unique<VisualHull>(box, config_.hull);
  ++hull_generation_;
  box_ = box;
  std::vector<Arrival> joining;
  for (Arrival& arrival : waiting_) {
    try {
      hull_->checkView(arrival.view);
      joining.push_back(std::move(arrival));
    } catch (const std::invalid_argument& e) {
      refuse(arrival.view.name(), arrival.serial, e.what());
    }
  }
  waiting_.clear();
  std::vector<HullView> views;
  for (const Arrival& arrival : joining) views.push_back(arrival.view);
  hull_->addViews(std::move(views));
  if (hull_->isEmpty()) {
    hull_->reset();
    ++hull_generation_;
    for (Arrival& arrival : joining) addToHull(std::move(arrival));
  }
  if (hull_->views().empty()) {  // every view refused: the next views bound a box afresh
    hull_.reset();
    why_no_box_ = "no waiting view could join the hull";
    return;
  }
  why_no_box_.clear();
}

void HullStream::reset() {
  redundant_views_ = 0;
  refits_ = 0;
  refused_views_ = 0;
  refusals_.clear();
  waiting_.clear();
  hull_.reset();
  why_no_box_ = "no view yet";
}

}  // namespace sift_hull
