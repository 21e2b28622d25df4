// The hull node's surface points and the refinement they make (on the worker): each pair merged
// or counted by reason; the refinement in slices of kRefineSlice_s, views carved between them.

#include <algorithm>

#include "lib/conversions.h"
#include "nodes/hull_node.h"

namespace sift_hull {
namespace {

/// Wall time of one slice of a refinement by the surface points; views are carved between slices.
constexpr double kRefineSlice_s = 0.05;

}  // namespace

void HullNode::takeSurfacePoints() {
  points_posted_ = false;
  PosedPoints posed;
  while (points_.pop(&posed)) mergeSurfacePoints(posed);
}

void HullNode::mergeSurfacePoints(const PosedPoints& posed) {
  const sift_hull::SurfacePoints& message = *posed.message;
  PinholeCamera left, right;
  std::vector<SurfacePoint> points;
  std::string why_not;
  const size_t max_points = static_cast<size_t>(config_.carving.max_points_per_pair);
  if (!ros_conversions::surfacePointsFromMessage(message, posed.T_W_F, &left, &right, &points,
                                                 &why_not, max_points)) {
    ++counts_.pairs_bad;
    problem("hull: surface points ignored: ", why_not);
    return;
  }
  counts_.points_subsampled += message.points.size() - points.size();
  const PointCarvedStream::AddedPoints added = hull_.addSurfacePoints(
      left, right, std::move(points), static_cast<int64_t>(message.header.stamp.toNSec()));
  counts_.points_outside += added.outside;
  if (!added.refused.empty()) {
    ++counts_.pairs_refused;
    problem("hull: surface points refused: ", added.refused);
  } else if (added.kept == 0) {
    ++counts_.pairs_empty;
  } else {
    ++counts_.pairs_merged;
  }
}

void HullNode::continueRefining() {
  // The next slice once the views waiting now are carved: the last of them posts it.
  if (work_.counts().waiting == 0 && !refine_posted_.exchange(true)) {
    work_.post([this] { refineIfDue(); });
  }
}

void HullNode::refineIfDue() {
  refine_posted_ = false;
  // The views that came since the last segmentation, once none waits: segmented with the rest.
  if (together_ && work_.counts().waiting == 0 && together_->segmentDue(true) &&
      segmentTogether()) {
    publishPending();
  }
  if (!hull_.refineDue()) return;
  try {
    const ros::WallTime start = ros::WallTime::now();
    if (!hull_.refining()) {  // a refinement begins
      refine_start_ = start;
      refine_slices_ms_ = 0.0;
    }
    PointCarvedStream::Refinement refinement;
    const bool done = hull_.refineFor(kRefineSlice_s, &refinement);
    const ros::WallTime end = ros::WallTime::now();
    refine_slices_ms_ = std::max(refine_slices_ms_, (end - start).toSec() * 1e3);
    if (!done) {
      continueRefining();
      return;
    }
    last_refine_ms_ = (end - refine_start_).toSec() * 1e3;
    longest_refine_slice_ms_ = refine_slices_ms_;
    counts_.free_voxels = refinement.free_voxels;
    counts_.pairs_refused += refinement.pairs_refused;
    if (refinement.pairs_refused > 0) {
      problem("hull: surface points refused: ",
              "a pair that came before the hull has a camera beyond ~max_distance_cube_edges");
    }
    ros::Time newest;
    newest.fromNSec(static_cast<uint64_t>(std::max<int64_t>(refinement.newest_stamp_ns, 0)));
    publish(std::max(newest, outputs_.header().stamp));
  } catch (const std::exception& e) {
    problem("hull: cannot carve with the surface points: ", e.what());
  }
}

}  // namespace sift_hull
