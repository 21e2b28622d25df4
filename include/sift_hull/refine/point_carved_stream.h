#pragma once

#include <cstddef>
#include <cstdint>
#include <deque>
#include <memory>
#include <mutex>
#include <string>
#include <vector>

#include "sift_hull/geometry/camera.h"
#include "sift_hull/hull/hull_stream.h"
#include "sift_hull/refine/free_space.h"
#include "sift_hull/refine/surface_points.h"
#include "sift_hull/settings.h"

namespace sift_hull {

/// Free-space carving of a streamed hull by the surface points of calibrated pairs that arrive
/// one pair at a time (the hull node's `surface_points`).
struct PointCarvingConfig {
  /// Surface points kept in all; beyond, the oldest pairs' points are dropped. A refinement
  /// carves with all of them at once (about 40 us a point at depth 8): this bounds its time.
  int max_surface_points = 50000;
  /// Points kept of one pair; a larger pair is subsampled evenly (in the message's order) to this
  /// many, and the rest counted.
  int max_points_per_pair = 20000;
  /// A pair's camera farther than this many edges of the hull's cube from its centre, or a point
  /// outside the cube grown by this many edges on each side, is refused: it carves nothing a
  /// camera near the object would not, and far enough it breaks the arithmetic.
  double max_distance_cube_edges = 1000.0;
  /// max_reprojection_px: a pair's points with a larger error are left out on arrival.
  /// (confirm_radius_voxels is unused: a pair's points carry no feature tracks.)
  SurfacePointConfig surface_points;
  FreeSpaceConfig free_space;
};
/// Its settings: names, units, ranges, help (sift_hull/settings.h); the nested structs without a
/// prefix.
template <>
const SettingTable<PointCarvingConfig>& settingsOf<PointCarvingConfig>();

/// Throws std::invalid_argument naming the first bad field.
void validate(const PointCarvingConfig& config);

/// A HullStream whose hull the kept surface points also carve (freeVoxels): the points wait until
/// the first box exists, and carve the tree again whenever it starts anew (a first box, a refit),
/// since the free voxels of the old tree are gone then.
///
/// Threads: addSurfacePoints may be called from any thread, also while another thread uses the
/// rest; the other members need one caller at a time.
class PointCarvedStream {
 public:
  /// Throws std::invalid_argument for a bad config (validate()).
  PointCarvedStream(HullStreamConfig stream, PointCarvingConfig points);

  /// HullStream::add.
  HullStream::Outcome add(const std::string& name, const PinholeCamera& camera,
                          const cv::Mat& mask);

  /// What became of one pair's points.
  struct AddedPoints {
    size_t kept = 0;
    size_t over_reprojection = 0;  ///< over max_reprojection_px (or NaN)
    size_t subsampled = 0;         ///< left out to keep max_points_per_pair
    size_t outside = 0;            ///< outside the cube's margin (max_distance_cube_edges)
    std::string refused;           ///< why the whole pair was refused (empty: it was not)
  };
  /// One pair's points, world frame (their views are replaced by the pair's two cameras), stamped
  /// `stamp_ns` (nanoseconds, any epoch). Points over max_reprojection_px are left out, the rest
  /// subsampled to max_points_per_pair. Once there is a hull, a pair whose camera lies beyond
  /// max_distance_cube_edges is refused and points beyond it are left out; pairs that came before
  /// the hull are checked so when it starts (refine() drops them, counted in Refinement).
  AddedPoints addSurfacePoints(const PinholeCamera& left, const PinholeCamera& right,
                               std::vector<SurfacePoint> points, int64_t stamp_ns);

  /// ~clear_bbx: the occupied finest voxels the box touches become free (VisualHull::carveFree:
  /// the maps and the mesh lose them), at once; returns how many. Requires stream().hasHull().
  /// When the tree starts anew (a refit of the box, only while views shrink it without a given
  /// box), the boxes cleared before are gone. Throws std::invalid_argument for a box that is not
  /// finite with min <= max, or that touches more than kMaxClearedVoxels occupied voxels.
  size_t clearBox(const Box3d& box_W);
  static constexpr size_t kMaxClearedVoxels = size_t{1} << 20;
  /// Free-space carving of the hull by voxels found elsewhere (photo carving:
  /// VisualHull::carveFree); gone, as clearBox's, when the tree starts anew. Requires
  /// stream().hasHull().
  void carveFree(const std::vector<Eigen::Vector3i>& voxels);

  /// Whether refine() has work: a hull, and a refinement not done (refineFor), points that arrived
  /// since the last refinement, or a tree that started anew while points are kept.
  bool refineDue();

  struct Refinement {
    size_t free_voxels = 0;       ///< the hull's free voxels afterwards
    size_t points_used = 0;       ///< kept points inside the hull
    int64_t newest_stamp_ns = 0;  ///< of the newest pair kept
    size_t pairs_refused = 0;     ///< waiting pairs whose camera lies beyond the cube's margin
  };
  /// Carves the hull with the free voxels of every point kept that lies inside it. Requires
  /// stream().hasHull().
  Refinement refine();
  /// refine() in slices of about `budget_s` of wall time (FreeSpaceCarving): false while work is
  /// left (call again; views may be added in between), true when the refinement is done and
  /// carved, with its result in `refinement`. The free voxels are judged on the hull as it was at
  /// the first slice and carved at the last, except those that views carved out meanwhile. A tree
  /// that starts anew, or reset(), begins the refinement again. Requires stream().hasHull().
  bool refineFor(double budget_s, Refinement* refinement);
  /// A refinement begun by refineFor and not done.
  bool refining() const { return carving_ != nullptr; }

  /// Back to no views, no hull and no points.
  void reset();
  /// Back to no views and no hull, the surface points kept: they carve the hull the views added
  /// next make at the next refinement (the views' silhouettes made anew).
  void restartViews();

  const HullStream& stream() const { return stream_; }
  /// HullStream::takeRefusals.
  std::vector<std::string> takeRefusals() { return stream_.takeRefusals(); }
  /// Surface points kept now.
  size_t storedPoints() const;
  /// The hull's free voxels after the last refine() (0 after reset()).
  size_t freeVoxelCount() const { return free_voxels_; }

 private:
  /// Why a camera is beyond the cube's margin (empty: it is not). Requires a hull.
  std::string farCamera(const PinholeCamera& camera) const;
  bool insideMargin(const Eigen::Vector3d& X_W) const;
  size_t dropFarPairs();

  struct PairPoints {
    PinholeCamera left, right;
    std::vector<SurfacePoint> points;
    int64_t stamp_ns = 0;
  };

  const PointCarvingConfig config_;
  HullStream stream_;
  mutable std::mutex points_mutex_;  ///< guards pairs_, stored_points_ and points_new_
  std::deque<PairPoints> pairs_;     ///< the kept points, oldest pair first
  size_t stored_points_ = 0;
  bool points_new_ = false;          ///< points arrived since the last refine()
  uint64_t refined_generation_ = 0;  ///< the stream's hull generation last carved with points
  size_t free_voxels_ = 0;
  // The refinement in progress (refineFor): its carving, the tree generation it judges, what it
  // found so far and its result but for the free voxels.
  std::unique_ptr<FreeSpaceCarving> carving_;
  uint64_t carving_generation_ = 0;
  std::vector<Eigen::Vector3i> carving_found_;
  Refinement carving_result_;
};

}  // namespace sift_hull
