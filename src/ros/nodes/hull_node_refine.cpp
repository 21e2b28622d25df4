// The hull node's free-space carving: surface points of calibrated pairs (matcher_node's
// `surface_points`) carve what the silhouettes cannot (src/core/refine).

#include <geometry_msgs/TransformStamped.h>
#include <tf2_eigen/tf2_eigen.h>

#include "lib/conversions.h"
#include "nodes/hull_node.h"

namespace sift_hull {

void HullNode::onSurfacePoints(const sift_hull::SurfacePointsConstPtr& message) {
  Eigen::Isometry3d T_W_F;
  try {
    T_W_F = tf2::transformToEigen(tf_buffer_.lookupTransform(
        config_.world_frame, message->header.frame_id, message->header.stamp, ros::Duration(0.5)));
  } catch (const tf2::TransformException& e) {
    log_.error("hull: surface points ignored: ", "no pose of '" + message->header.frame_id +
                                                     "' in '" + config_.world_frame +
                                                     "' at their stamp (" + e.what() + ")");
    return;
  }
  PairPoints pair;
  std::string why_not;
  if (!ros_conversions::surfacePointsFromMessage(*message, T_W_F, &pair.left, &pair.right,
                                                 &pair.points, &why_not)) {
    log_.error("hull: surface points ignored: ", why_not);
    return;
  }
  std::vector<SurfacePoint> kept;
  for (const SurfacePoint& point : pair.points) {
    if (point.reprojection_px <= config_.surface_points.max_reprojection_px) kept.push_back(point);
  }
  if (kept.empty()) return;
  pair.points = std::move(kept);
  pair.stamp = message->header.stamp;
  std::lock_guard<std::mutex> lock(points_mutex_);
  stored_points_ += pair.points.size();
  pairs_.push_back(std::move(pair));
  while (stored_points_ > static_cast<size_t>(config_.max_surface_points) && pairs_.size() > 1) {
    stored_points_ -= pairs_.front().points.size();
    pairs_.pop_front();
  }
  refine_pending_ = true;
}

void HullNode::refineIfDue() {
  {
    std::lock_guard<std::mutex> lock(points_mutex_);
    if (!refine_pending_) return;
  }
  std::lock_guard<std::mutex> lock(hull_mutex_);
  if (!stream_.hasHull()) return;  // the points wait for the first box
  try {
    refineWithPoints();
  } catch (const std::exception& e) {
    log_.error("hull: cannot carve with the surface points: ", e.what());
  }
}

void HullNode::refineWithPoints() {
  std::vector<PinholeCamera> cameras;
  std::vector<SurfacePoint> points;
  ros::Time newest;
  {
    std::lock_guard<std::mutex> lock(points_mutex_);
    refine_pending_ = false;
    for (const PairPoints& pair : pairs_) {
      const uint32_t first = static_cast<uint32_t>(cameras.size());
      cameras.push_back(pair.left);
      cameras.push_back(pair.right);
      for (SurfacePoint point : pair.points) {
        if (stream_.hull().leafAt(point.X_W).state == CellState::kOut) continue;
        point.views = {first, first + 1};
        points.push_back(std::move(point));
      }
      newest = std::max(newest, pair.stamp);
    }
  }
  const std::vector<Eigen::Vector3i> free =
      freeVoxels(stream_.hull(), cameras, points, config_.free_space);
  stream_.carveFree(free);
  refined_generation_ = stream_.hullGeneration();
  free_voxels_ = stream_.hull().freeVoxelCount();
  publish(std::max(newest, header_.stamp));
}

}  // namespace sift_hull
