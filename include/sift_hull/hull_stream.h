#pragma once

#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "sift_hull/visual_hull.h"

namespace sift_hull {

/// Settings of a hull built from views that arrive one at a time.
struct HullStreamConfig {
  HullConfig hull;
  /// The box to carve, world frame; empty: the LP box (eq. 8) of the first views that bound one.
  std::optional<Box3d> box;
  std::vector<std::string> skip_views;  ///< view names left out (bad silhouettes)
  /// A view whose camera centre lies within min_view_distance_m of a view already taken and
  /// whose optical axis is within min_view_angle_deg of that view's sees nothing new: it is left
  /// out (kRedundant). The hull keeps every view it takes, so without this a camera standing
  /// still on a 30 Hz stream would grow it by a view per frame. 0 and 0 take every view.
  double min_view_distance_m = 0.01;
  double min_view_angle_deg = 1.0;
};

/// Throws std::invalid_argument for a negative or non-finite distance, or an angle outside
/// [0, 180] degrees.
void validate(const HullStreamConfig& config);

/// A visual hull that views refine as they arrive (the hull node's worker). Until a box exists,
/// views wait; the first time the LP over the waiting views gives a box, the hull is carved with
/// all of them; every later view refines it (VisualHull::addView).
class HullStream {
 public:
  explicit HullStream(HullStreamConfig config);

  enum class Outcome {
    kCarved,     ///< the hull exists and includes the view
    kWaiting,    ///< no box yet: the view waits for more
    kSkipped,    ///< named in skip_views
    kRedundant,  ///< seen from where a view already taken was (min_view_distance_m)
  };
  /// Throws std::invalid_argument for a bad mask (see HullView).
  Outcome add(const std::string& name, const PinholeCamera& camera, const cv::Mat& mask);

  /// Back to no views and no hull.
  void reset();
  /// Views left out as redundant since the start or the last reset.
  size_t redundantViews() const { return redundant_views_; }

  bool hasHull() const { return hull_ != nullptr; }
  /// Requires hasHull().
  const VisualHull& hull() const { return *hull_; }
  size_t waitingViews() const { return waiting_.size(); }
  /// Why the waiting views give no box yet (empty when there is a hull).
  const std::string& whyNoBox() const { return why_no_box_; }

 private:
  void tryToStart();
  bool isRedundant(const PinholeCamera& camera) const;

  struct Viewpoint {
    Eigen::Vector3d centre, axis;
  };

  HullStreamConfig config_;
  std::vector<Viewpoint> taken_;  ///< of the waiting and the carved views
  size_t redundant_views_ = 0;
  std::vector<HullView> waiting_;
  std::unique_ptr<VisualHull> hull_;
  std::string why_no_box_ = "no view yet";
};

}  // namespace sift_hull
