#pragma once

#include <cstdint>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "sift_hull/hull/octree.h"
#include "sift_hull/settings.h"

namespace sift_hull {

/// Settings of a hull built from views that arrive one at a time.
struct HullStreamConfig {
  HullConfig hull;
  /// The box to carve, world frame; empty: the LP box (eq. 8) of the first views that bound one.
  /// A view whose camera sees the given box behind it (the centre at depth <= 0) is refused.
  std::optional<Box3d> box;
  std::vector<std::string> skip_views;  ///< view names left out (bad silhouettes)
  /// A view whose camera centre lies within min_view_distance_m of a view already taken and
  /// whose optical axis is within min_view_angle_deg of that view's sees nothing new: it is left
  /// out (kRedundant). The hull keeps every view it takes, so without this a camera standing
  /// still on a 30 Hz stream would grow it by a view per frame. 0 and 0 take every view.
  double min_view_distance_m = 0.01;
  double min_view_angle_deg = 1.0;
  /// Views waiting for a box at most; when one more comes, the oldest waiting view is refused,
  /// so that views that never bound a box (parallel rays, a bad calibration) cannot pile up.
  int max_waiting_views = 16;
  /// Views the hull takes at most (each keeps its distance map, about 8 bytes per pixel of its
  /// silhouette's box, or per sample of a reduced map: views that come once the hull has its box
  /// are sampled at the reduction it allows, distanceReduction); later views are refused.
  int max_views = 1000;
};
/// Its settings: names, units, ranges, help (sift_hull/settings.h).
template <>
const SettingTable<HullStreamConfig>& settingsOf<HullStreamConfig>();

/// Throws std::invalid_argument for a negative or non-finite distance, an angle outside
/// [0, 180] degrees, view counts below 2 (waiting) or 1, or a box the octree cannot hold.
void validate(const HullStreamConfig& config);

/// A visual hull that views refine as they arrive (the hull node's worker). Until a box exists,
/// views wait; the first time the LP over the waiting views gives a box, the hull is carved with
/// all of them; every later view refines it (VisualHull::addView). Without a given box, a view
/// that shrinks the LP box of the views taken by more than a cell has the hull carved again in
/// the smaller box (refits()), so that box and resolution follow `sift_hull hull` on the same
/// views.
///
/// Bad views are refused with a reason (kRefused, whyRefused()) and leave the stream as if they
/// never came:
/// - a silhouette that covers no pixel or every pixel of its image;
/// - once the hull exists, a view that would carve it to nothing, or that cannot join it (its
///   camera too far from the box for single precision, or inside a voxel);
/// - while waiting: a view whose cone misses the others' (the LP is empty with it and not empty
///   without it, and that holds for it alone), and the oldest waiting view once more than
///   max_waiting_views wait;
/// - views beyond max_views.
/// After a waiting view is refused, the views that waited with it are taken again in their order,
/// so the box forms when it would have formed without the refused view.
class HullStream {
 public:
  explicit HullStream(HullStreamConfig config);

  enum class Outcome {
    kCarved,     ///< the hull exists and includes the view
    kWaiting,    ///< no box yet: the view waits for more
    kSkipped,    ///< named in skip_views
    kRedundant,  ///< seen from where a view already taken was (min_view_distance_m)
    kRefused,    ///< a bad view, left out (whyRefused())
  };
  /// Throws std::invalid_argument for a bad mask (see HullView).
  Outcome add(const std::string& name, const PinholeCamera& camera, const cv::Mat& mask);

  /// Back to no views and no hull.
  void reset();
  /// Views left out as redundant since the start or the last reset.
  size_t redundantViews() const { return redundant_views_; }
  /// Views refused since the start or the last reset, and why the last one was; a waiting view
  /// refused while a later view was added counts too (see takeRefusals).
  size_t refusedViews() const { return refused_views_; }
  /// The refusals since the last call, each "view 'NAME': reason", oldest first.
  std::vector<std::string> takeRefusals();

  bool hasHull() const { return hull_ != nullptr; }
  /// Requires hasHull().
  const VisualHull& hull() const { return *hull_; }
  size_t waitingViews() const { return waiting_.size(); }
  /// The box the hull is carved in: the given one, or the LP box of the views taken, refitted
  /// when a view shrinks it by more than a cell (the hull then carved again). Requires hasHull().
  const Box3d& box() const { return box_; }
  /// How often the hull was carved again in a smaller box since the start or the last reset.
  size_t refits() const { return refits_; }
  /// Changes whenever the tree starts again (a first box, a refit, the views carved anew): free
  /// voxels carved into the old tree are gone then.
  uint64_t hullGeneration() const { return hull_generation_; }
  /// Free-space carving of the hull (VisualHull::carveFree). Requires hasHull().
  void carveFree(const std::vector<Eigen::Vector3i>& voxels) { hull_->carveFree(voxels); }
  /// Why the waiting views give no box yet (empty when there is a hull).
  const std::string& whyNoBox() const { return why_no_box_; }

 private:
  /// A view with the number of its arrival, so that a refusal knows whether it is the newest.
  struct Arrival {
    HullView view;
    uint64_t serial;
  };

  HullView viewOf(const std::string& name, const PinholeCamera& camera, const cv::Mat& mask) const;
  void take(Arrival arrival);
  void wait(Arrival arrival);
  void tryToStart();
  void startHull(const Box3d& box);
  void dropViewMissingTheOthers();
  void replay(std::vector<Arrival> arrivals);
  void addToHull(Arrival arrival);
  void refitBox();
  void refuse(const std::string& name, uint64_t serial, const std::string& reason);
  bool isRedundant(const PinholeCamera& camera) const;

  HullStreamConfig config_;
  size_t redundant_views_ = 0;
  size_t refused_views_ = 0;
  std::vector<std::string> refusals_;
  uint64_t arrivals_ = 0;        ///< serial of the newest view
  bool newest_refused_ = false;  ///< whether the newest view was refused
  std::vector<Arrival> waiting_;
  std::unique_ptr<VisualHull> hull_;
  Box3d box_;  ///< the hull's
  uint64_t hull_generation_ = 0;
  size_t refits_ = 0;
  std::string why_no_box_ = "no view yet";
};

}  // namespace sift_hull
