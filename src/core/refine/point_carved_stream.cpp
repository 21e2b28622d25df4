#include "sift_hull/refine/point_carved_stream.h"

#include <algorithm>
#include <utility>

namespace sift_hull {

template <>
const SettingTable<PointCarvingConfig>& settingsOf<PointCarvingConfig>() {
  static const SettingTable<PointCarvingConfig> table = [] {
    SettingTable<PointCarvingConfig> t;
    t.add("max_surface_points", &PointCarvingConfig::max_surface_points, "points",
          "surface points kept for free-space carving; beyond, the oldest pairs' go")
        .atLeast(1);
    // Confirming points by feature tracks needs tracks, which a pair's points lack.
    t.nest("", &PointCarvingConfig::surface_points, settingsOf<SurfacePointConfig>(),
           {"confirm_radius_voxels"});
    t.nest("", &PointCarvingConfig::free_space, settingsOf<FreeSpaceConfig>());
    return t;
  }();
  return table;
}

void validate(const PointCarvingConfig& config) { checkSettings(config, "PointCarvingConfig"); }

PointCarvedStream::PointCarvedStream(HullStreamConfig stream, PointCarvingConfig points)
    : config_((validate(points), std::move(points))), stream_(std::move(stream)) {}

HullStream::Outcome PointCarvedStream::add(const std::string& name, const PinholeCamera& camera,
                                           const cv::Mat& mask) {
  return stream_.add(name, camera, mask);
}

size_t PointCarvedStream::addSurfacePoints(const PinholeCamera& left, const PinholeCamera& right,
                                           std::vector<SurfacePoint> points, int64_t stamp_ns) {
  const double max_px = config_.surface_points.max_reprojection_px;
  points.erase(
      std::remove_if(points.begin(), points.end(),
                     [max_px](const SurfacePoint& p) { return !(p.reprojection_px <= max_px); }),
      points.end());
  const size_t kept = points.size();
  if (kept == 0) return 0;
  std::lock_guard<std::mutex> lock(points_mutex_);
  stored_points_ += kept;
  pairs_.push_back({left, right, std::move(points), stamp_ns});
  while (stored_points_ > static_cast<size_t>(config_.max_surface_points) && pairs_.size() > 1) {
    stored_points_ -= pairs_.front().points.size();
    pairs_.pop_front();
  }
  points_new_ = true;
  return kept;
}

bool PointCarvedStream::refineDue() {
  if (!stream_.hasHull()) return false;  // the points wait for the first box
  std::lock_guard<std::mutex> lock(points_mutex_);
  if (pairs_.empty()) return false;
  return points_new_ || stream_.hullGeneration() != refined_generation_;
}

PointCarvedStream::Refinement PointCarvedStream::refine() {
  std::vector<PinholeCamera> cameras;
  std::vector<SurfacePoint> points;
  Refinement refinement;
  {
    std::lock_guard<std::mutex> lock(points_mutex_);
    points_new_ = false;
    for (const PairPoints& pair : pairs_) {
      const uint32_t first = static_cast<uint32_t>(cameras.size());
      cameras.push_back(pair.left);
      cameras.push_back(pair.right);
      for (SurfacePoint point : pair.points) {
        if (stream_.hull().leafAt(point.X_W).state == CellState::kOut) continue;
        point.views = {first, first + 1};
        points.push_back(std::move(point));
      }
      refinement.newest_stamp_ns = std::max(refinement.newest_stamp_ns, pair.stamp_ns);
    }
  }
  stream_.carveFree(sift_hull::freeVoxels(stream_.hull(), cameras, points, config_.free_space));
  refined_generation_ = stream_.hullGeneration();
  free_voxels_ = stream_.hull().freeVoxelCount();
  refinement.free_voxels = free_voxels_;
  refinement.points_used = points.size();
  return refinement;
}

void PointCarvedStream::reset() {
  stream_.reset();
  std::lock_guard<std::mutex> lock(points_mutex_);
  pairs_.clear();
  stored_points_ = 0;
  points_new_ = false;
  refined_generation_ = 0;
  free_voxels_ = 0;
}

size_t PointCarvedStream::storedPoints() const {
  std::lock_guard<std::mutex> lock(points_mutex_);
  return stored_points_;
}

}  // namespace sift_hull
