#include "sift_hull/refine/surface_points.h"

#include <algorithm>
#include <cmath>
#include <optional>
#include <stdexcept>
#include <string>
#include <unordered_map>

namespace sift_hull {
namespace {

/// Below this sine of the angle between a pair's rays the depth is not resolved at all.
constexpr double kMinRaySine = 1e-3;

/// A triangulated match with its pair.
struct Candidate {
  SurfacePoint point;
  size_t pair = 0;
  int left_keypoint = -1, right_keypoint = -1;  ///< -1: not given
};

std::optional<Candidate> triangulated(const PinholeCamera& left, const PinholeCamera& right,
                                      const Eigen::Vector2d& left_px,
                                      const Eigen::Vector2d& right_px, size_t pair) {
  const std::optional<Eigen::Vector2d> ideal_left = left.undistortPixel(left_px);
  const std::optional<Eigen::Vector2d> ideal_right = right.undistortPixel(right_px);
  if (!ideal_left || !ideal_right) return std::nullopt;
  const std::optional<Eigen::Vector3d> X = triangulate(left, right, *ideal_left, *ideal_right);
  if (!X || !X->allFinite()) return std::nullopt;
  Candidate candidate;
  candidate.pair = pair;
  SurfacePoint& point = candidate.point;
  point.X_W = *X;
  point.reprojection_px =
      std::max((left.project(*X) - left_px).norm(), (right.project(*X) - right_px).norm());
  point.depth_sigma_m = depthSigma(left, right, *X, point.reprojection_px);
  return candidate;
}

bool insideHull(const VisualHull& hull, const Eigen::Vector3d& X_W) {
  return hull.leafAt(X_W).state != CellState::kOut;
}

void checkPairs(const std::vector<PinholeCamera>& cameras, const std::vector<PairMatches>& pairs) {
  for (const PairMatches& pair : pairs) {
    if (pair.left_view >= cameras.size() || pair.right_view >= cameras.size() ||
        pair.left_view == pair.right_view) {
      throw std::invalid_argument("surfacePoints: a pair of views " +
                                  std::to_string(pair.left_view) + " and " +
                                  std::to_string(pair.right_view) + " among " +
                                  std::to_string(cameras.size()) + " cameras");
    }
    const bool ids = !pair.left_keypoint.empty() || !pair.right_keypoint.empty();
    if (pair.left_px.size() != pair.right_px.size() ||
        (ids && (pair.left_keypoint.size() != pair.left_px.size() ||
                 pair.right_keypoint.size() != pair.right_px.size()))) {
      throw std::invalid_argument("surfacePoints: a pair with " +
                                  std::to_string(pair.left_px.size()) + " left and " +
                                  std::to_string(pair.right_px.size()) + " right pixels");
    }
  }
}

}  // namespace

double depthSigma(const PinholeCamera& a, const PinholeCamera& b, const Eigen::Vector3d& X,
                  double reprojection_px) {
  const Eigen::Vector3d ray_a = (X - a.centre()).normalized();
  const Eigen::Vector3d ray_b = (X - b.centre()).normalized();
  const double sine = std::max(ray_a.cross(ray_b).norm(), kMinRaySine);
  const double focal_px = 0.25 * (a.K()(0, 0) + a.K()(1, 1) + b.K()(0, 0) + b.K()(1, 1));
  const double depth_m = std::max(a.depth(X), b.depth(X));
  return std::max(reprojection_px, 0.5) * depth_m / focal_px / sine;
}

std::vector<SurfacePoint> triangulatePair(const PinholeCamera& left, const PinholeCamera& right,
                                          const PairMatches& pair) {
  if (pair.left_px.size() != pair.right_px.size()) {
    throw std::invalid_argument("triangulatePair: " + std::to_string(pair.left_px.size()) +
                                " left and " + std::to_string(pair.right_px.size()) +
                                " right pixels");
  }
  std::vector<SurfacePoint> points;
  for (size_t m = 0; m < pair.left_px.size(); ++m) {
    const std::optional<Candidate> candidate =
        triangulated(left, right, pair.left_px[m], pair.right_px[m], 0);
    if (!candidate) continue;
    points.push_back(candidate->point);
    points.back().views = {pair.left_view, pair.right_view};
  }
  return points;
}


std::vector<SurfacePoint> surfacePoints(const std::vector<PinholeCamera>& cameras,
                                        const std::vector<PairMatches>& pairs,
                                        const VisualHull& hull, const SurfacePointConfig& config,
                                        SurfacePointCounts* counts) {
  validate(config);
  checkPairs(cameras, pairs);
  SurfacePointCounts local;
  SurfacePointCounts& n = counts != nullptr ? *counts : local;
  n = SurfacePointCounts{};
  std::vector<Candidate> candidates;
  for (size_t p = 0; p < pairs.size(); ++p) {
    const PairMatches& pair = pairs[p];
    for (size_t m = 0; m < pair.left_px.size(); ++m) {
      const std::optional<Candidate> candidate = triangulated(
          cameras[pair.left_view], cameras[pair.right_view], pair.left_px[m], pair.right_px[m], p);
      if (!candidate) continue;
      ++n.triangulated;
      if (!(candidate->point.reprojection_px <= config.max_reprojection_px)) continue;
      ++n.reprojected;
      if (!insideHull(hull, candidate->point.X_W)) continue;
      ++n.inside_hull;
      candidates.push_back(*candidate);
      candidates.back().point.views = {pair.left_view, pair.right_view};
      if (!pair.left_keypoint.empty()) {
        candidates.back().left_keypoint = pair.left_keypoint[m];
        candidates.back().right_keypoint = pair.right_keypoint[m];
      }
    }
  }
  // Features: (view, keypoint) -> the candidates that hold it.
  std::unordered_map<uint64_t, std::vector<size_t>> by_feature;
  const auto feature = [](uint32_t view, int keypoint) {
    return (static_cast<uint64_t>(view) << 32) | static_cast<uint32_t>(keypoint);
  };
  for (size_t i = 0; i < candidates.size(); ++i) {
    const Candidate& c = candidates[i];
    if (c.left_keypoint < 0) continue;
    by_feature[feature(pairs[c.pair].left_view, c.left_keypoint)].push_back(i);
    by_feature[feature(pairs[c.pair].right_view, c.right_keypoint)].push_back(i);
  }
  const double radius_m = config.confirm_radius_voxels * hull.cube().resolution_m;
  std::vector<SurfacePoint> points;
  for (size_t i = 0; i < candidates.size(); ++i) {
    const Candidate& candidate = candidates[i];
    SurfacePoint point = candidate.point;
    bool others = false, confirmed = false;
    if (candidate.left_keypoint >= 0) {
      const PairMatches& pair = pairs[candidate.pair];
      for (const uint64_t key : {feature(pair.left_view, candidate.left_keypoint),
                                 feature(pair.right_view, candidate.right_keypoint)}) {
        for (const size_t other : by_feature[key]) {
          if (other == i) continue;
          others = true;
          const Candidate& near = candidates[other];
          if ((near.point.X_W - point.X_W).norm() > radius_m) continue;
          confirmed = true;
          point.views.insert(point.views.end(), near.point.views.begin(), near.point.views.end());
        }
      }
    }
    if (others && !confirmed) continue;  // another pair saw this feature elsewhere
    n.confirmed += confirmed ? 1 : 0;
    std::sort(point.views.begin(), point.views.end());
    point.views.erase(std::unique(point.views.begin(), point.views.end()), point.views.end());
    points.push_back(std::move(point));
  }
  n.kept = points.size();
  return points;
}

}  // namespace sift_hull
