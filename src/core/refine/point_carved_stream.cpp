#include "sift_hull/refine/point_carved_stream.h"

#include <algorithm>
#include <limits>
#include <sstream>
#include <stdexcept>
#include <utility>

#include "sift_hull/hull/hull_octomap.h"

namespace sift_hull {

template <>
const SettingTable<PointCarvingConfig>& settingsOf<PointCarvingConfig>() {
  static const SettingTable<PointCarvingConfig> table = [] {
    SettingTable<PointCarvingConfig> t;
    t.add("max_surface_points", &PointCarvingConfig::max_surface_points, "points",
          "surface points kept for free-space carving; beyond, the oldest pairs' go (a "
          "refinement carves with all of them: about 40 us a point at depth 8)")
        .atLeast(1);
    t.add("max_points_per_pair", &PointCarvingConfig::max_points_per_pair, "points",
          "points kept of one pair of surface points; a larger pair is subsampled evenly")
        .atLeast(1);
    t.add("max_distance_cube_edges", &PointCarvingConfig::max_distance_cube_edges, "cube edges",
          "a pair's camera farther from the hull's cube, or a point farther outside it, than "
          "this many edges of the cube is refused")
        .atLeast(1.0);
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

namespace {

/// Keeps `keep` of `points` evenly spread in their order.
void subsample(std::vector<SurfacePoint>* points, size_t keep) {
  const size_t n = points->size();
  if (n <= keep) return;
  std::vector<SurfacePoint> kept;
  kept.reserve(keep);
  for (size_t i = 0; i < keep; ++i) kept.push_back(std::move((*points)[i * n / keep]));
  points->swap(kept);
}

template <typename T, typename Predicate>
size_t eraseIf(std::vector<T>* points, Predicate predicate) {
  const size_t before = points->size();
  points->erase(std::remove_if(points->begin(), points->end(), predicate), points->end());
  return before - points->size();
}

}  // namespace

std::string PointCarvedStream::farCamera(const PinholeCamera& camera) const {
  const HullCube& cube = stream_.hull().cube();
  const Eigen::Vector3d centre = camera.centre();
  const double distance_m = (centre - cube.box().centre()).norm();
  if (distance_m <= config_.max_distance_cube_edges * cube.edge_m()) return {};
  std::ostringstream out;
  out << "a camera at (" << centre.x() << ", " << centre.y() << ", " << centre.z() << ") lies "
      << distance_m << " m from the hull's cube of edge " << cube.edge_m()
      << " m, beyond ~max_distance_cube_edges (" << config_.max_distance_cube_edges << ")";
  return out.str();
}

bool PointCarvedStream::insideMargin(const Eigen::Vector3d& X_W) const {
  const HullCube& cube = stream_.hull().cube();
  return cube.box().contains(X_W, config_.max_distance_cube_edges * cube.edge_m());
}

PointCarvedStream::AddedPoints PointCarvedStream::addSurfacePoints(const PinholeCamera& left,
                                                                   const PinholeCamera& right,
                                                                   std::vector<SurfacePoint> points,
                                                                   int64_t stamp_ns) {
  AddedPoints added;
  if (stream_.hasHull()) {
    added.refused = farCamera(left);
    if (added.refused.empty()) added.refused = farCamera(right);
    if (!added.refused.empty()) return added;
    added.outside =
        eraseIf(&points, [this](const SurfacePoint& p) { return !insideMargin(p.X_W); });
  }
  const double max_px = config_.surface_points.max_reprojection_px;
  added.over_reprojection =
      eraseIf(&points, [max_px](const SurfacePoint& p) { return !(p.reprojection_px <= max_px); });
  const size_t before = points.size();
  subsample(&points, static_cast<size_t>(config_.max_points_per_pair));
  added.subsampled = before - points.size();
  added.kept = points.size();
  if (added.kept == 0) return added;
  std::lock_guard<std::mutex> lock(points_mutex_);
  stored_points_ += added.kept;
  pairs_.push_back({left, right, std::move(points), stamp_ns});
  while (stored_points_ > static_cast<size_t>(config_.max_surface_points) && pairs_.size() > 1) {
    stored_points_ -= pairs_.front().points.size();
    pairs_.pop_front();
  }
  points_new_ = true;
  return added;
}

size_t PointCarvedStream::dropFarPairs() {
  std::lock_guard<std::mutex> lock(points_mutex_);
  const size_t before = pairs_.size();
  for (auto it = pairs_.begin(); it != pairs_.end();) {
    if (farCamera(it->left).empty() && farCamera(it->right).empty()) {
      stored_points_ -=
          eraseIf(&it->points, [this](const SurfacePoint& p) { return !insideMargin(p.X_W); });
      ++it;
    } else {
      stored_points_ -= it->points.size();
      it = pairs_.erase(it);
    }
  }
  return before - pairs_.size();
}

void PointCarvedStream::carveFree(const std::vector<Eigen::Vector3i>& voxels) {
  stream_.carveFree(voxels);
  free_voxels_ = stream_.hull().freeVoxelCount();
}

size_t PointCarvedStream::clearBox(const Box3d& box_W) {
  if (!isValidClearBox(box_W)) {
    throw std::invalid_argument("a box to clear must be finite with min <= max on each axis");
  }
  const std::vector<Eigen::Vector3i> voxels =
      occupiedVoxelsIn(stream_.hull(), box_W, kMaxClearedVoxels);
  stream_.carveFree(voxels);
  free_voxels_ = stream_.hull().freeVoxelCount();
  return voxels.size();
}

bool PointCarvedStream::refineDue() {
  if (!stream_.hasHull()) return false;  // the points wait for the first box
  if (carving_) return true;             // a refinement not done
  std::lock_guard<std::mutex> lock(points_mutex_);
  if (pairs_.empty()) return false;
  return points_new_ || stream_.hullGeneration() != refined_generation_;
}

PointCarvedStream::Refinement PointCarvedStream::refine() {
  Refinement refinement;
  while (!refineFor(std::numeric_limits<double>::infinity(), &refinement)) {
  }
  return refinement;
}

bool PointCarvedStream::refineFor(double budget_s, Refinement* refinement) {
  if (carving_ && stream_.hullGeneration() != carving_generation_) carving_.reset();
  if (!carving_) {  // a refinement begins: every point kept that lies inside the hull
    std::vector<PinholeCamera> cameras;
    std::vector<SurfacePoint> points;
    carving_result_ = Refinement();
    carving_result_.pairs_refused = dropFarPairs();
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
        carving_result_.newest_stamp_ns = std::max(carving_result_.newest_stamp_ns, pair.stamp_ns);
      }
    }
    carving_result_.points_used = points.size();
    carving_found_.clear();
    carving_ = std::make_unique<FreeSpaceCarving>(stream_.hull(), std::move(cameras),
                                                  std::move(points), config_.free_space);
    carving_generation_ = stream_.hullGeneration();
  }
  try {
    if (!carving_->step(budget_s, &carving_found_)) return false;
  } catch (...) {  // not begun again and again: the next refinement starts afresh
    carving_.reset();
    carving_found_ = {};
    throw;
  }
  // Views carved while the slices ran: what they made out is not free space.
  const HullCube& cube = stream_.hull().cube();
  eraseIf(&carving_found_, [&](const Eigen::Vector3i& voxel) {
    const Eigen::Vector3d centre_W =
        cube.origin_W() + (voxel.cast<double>().array() + 0.5).matrix() * cube.resolution_m;
    return stream_.hull().leafAt(centre_W).state == CellState::kOut;
  });
  stream_.carveFree(carving_found_);
  carving_.reset();
  carving_found_ = {};
  refined_generation_ = carving_generation_;
  free_voxels_ = stream_.hull().freeVoxelCount();
  *refinement = carving_result_;
  refinement->free_voxels = free_voxels_;
  return true;
}

void PointCarvedStream::reset() {
  stream_.reset();
  carving_.reset();
  carving_found_ = {};
  std::lock_guard<std::mutex> lock(points_mutex_);
  pairs_.clear();
  stored_points_ = 0;
  points_new_ = false;
  refined_generation_ = 0;
  free_voxels_ = 0;
}

void PointCarvedStream::restartViews() {
  stream_.reset();
  carving_.reset();
  carving_found_ = {};
  std::lock_guard<std::mutex> lock(points_mutex_);
  points_new_ = stored_points_ > 0;
  refined_generation_ = 0;
  free_voxels_ = 0;
}

size_t PointCarvedStream::storedPoints() const {
  std::lock_guard<std::mutex> lock(points_mutex_);
  return stored_points_;
}

}  // namespace sift_hull
