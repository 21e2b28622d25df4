// Free space from surface points: per view, the Delaunay triangulation of the points it saw,
// projected, is rasterised into a depth map (perspective-correct, the nearest triangle winning);
// every occupied finest voxel of the hull whose centre lies in front of enough views' depth maps
// by the margin is free.

#include "sift_hull/refine/free_space.h"

#include <algorithm>
#include <array>
#include <chrono>
#include <cmath>
#include <limits>
#include <map>
#include <mutex>
#include <opencv2/imgproc.hpp>
#include <stdexcept>
#include <string>
#include <tuple>
#include <unordered_set>

#include "common/parallel.h"
#include "hull/voxel_key.h"

namespace sift_hull {
namespace {

/// A view's surface as a depth map over the box of its points' ideal pixels.
struct ViewSurface {
  const PinholeCamera* camera = nullptr;
  Eigen::Vector2i origin_px = Eigen::Vector2i::Zero();
  cv::Mat depth_m;  ///< CV_32FC1, infinity where no triangle covers the pixel
  cv::Mat slack_m;  ///< CV_32FC1, the covering triangle's margin beyond the fixed one

  /// Whether the point lies in front of the surface by the margin (margin_m plus the slack).
  bool seesEmpty(const Eigen::Vector3d& X_W, double margin_m) const {
    const double depth = camera->depth(X_W);
    if (!(depth > 0.0)) return false;
    const Eigen::Vector2d px = camera->projectIdeal(X_W);
    const int u = static_cast<int>(std::lround(px.x())) - origin_px.x();
    const int v = static_cast<int>(std::lround(px.y())) - origin_px.y();
    if (u < 0 || v < 0 || u >= depth_m.cols || v >= depth_m.rows) return false;
    const float surface = depth_m.at<float>(v, u);
    return std::isfinite(surface) && depth < surface - margin_m - slack_m.at<float>(v, u);
  }
};

struct Corner {
  Eigen::Vector2d px;
  double depth_m, sigma_m;
  Eigen::Vector3d X_W;
};

/// Rasterises a triangle, depth interpolated in 1 / depth (perspective-correct), nearest wins,
/// with its slack: two of its corners' largest depth_sigma_m and its bulge.
void rasterise(const std::array<Corner, 3>& t, double bulge_m, ViewSurface* surface) {
  const Eigen::Vector2d lo = t[0].px.cwiseMin(t[1].px).cwiseMin(t[2].px);
  const Eigen::Vector2d hi = t[0].px.cwiseMax(t[1].px).cwiseMax(t[2].px);
  const double area = (t[1].px - t[0].px).x() * (t[2].px - t[0].px).y() -
                      (t[1].px - t[0].px).y() * (t[2].px - t[0].px).x();
  if (std::abs(area) < 1e-9) return;
  const float slack =
      static_cast<float>(2.0 * std::max({t[0].sigma_m, t[1].sigma_m, t[2].sigma_m}) + bulge_m);
  for (int v = static_cast<int>(std::ceil(lo.y())); v <= static_cast<int>(std::floor(hi.y()));
       ++v) {
    for (int u = static_cast<int>(std::ceil(lo.x())); u <= static_cast<int>(std::floor(hi.x()));
         ++u) {
      const Eigen::Vector2d p(u, v);
      double w[3];
      for (int i = 0; i < 3; ++i) {
        const Eigen::Vector2d& a = t[(i + 1) % 3].px;
        const Eigen::Vector2d& b = t[(i + 2) % 3].px;
        w[i] = ((b - a).x() * (p - a).y() - (b - a).y() * (p - a).x()) / area;
      }
      if (w[0] < 0.0 || w[1] < 0.0 || w[2] < 0.0) continue;
      const double inverse = w[0] / t[0].depth_m + w[1] / t[1].depth_m + w[2] / t[2].depth_m;
      const int x = u - surface->origin_px.x(), y = v - surface->origin_px.y();
      float& depth = surface->depth_m.at<float>(y, x);
      const float here = static_cast<float>(1.0 / inverse);
      if (here < depth) {
        depth = here;
        surface->slack_m.at<float>(y, x) = slack;
      }
    }
  }
}

/// The Delaunay triangulation of the corners' pixels, and each corner's neighbours in it (corners
/// at one pixel share its vertex: the first of them holds it).
cv::Subdiv2D delaunayOf(const std::vector<Corner>& corners, const cv::Rect& bounds,
                        std::vector<std::vector<size_t>>* neighbours) {
  cv::Subdiv2D delaunay(bounds);
  std::map<int, size_t> corner_of;  // Subdiv2D vertex id -> corner
  for (size_t i = 0; i < corners.size(); ++i) {
    const cv::Point2f p(static_cast<float>(corners[i].px.x()),
                        static_cast<float>(corners[i].px.y()));
    corner_of.emplace(delaunay.insert(p), i);
  }
  neighbours->assign(corners.size(), {});
  std::vector<int> leading;
  delaunay.getLeadingEdgeList(leading);
  for (const int edge : leading) {
    for (const int e : {edge, delaunay.rotateEdge(edge, 2)}) {
      const auto from = corner_of.find(delaunay.edgeOrg(e));
      const auto to = corner_of.find(delaunay.edgeDst(e));
      if (from != corner_of.end() && to != corner_of.end()) {
        (*neighbours)[from->second].push_back(to->second);
      }
    }
  }
  return delaunay;
}

/// The surface view `view` sees through its points; empty (no depth map) with fewer than three.
ViewSurface viewSurface(const PinholeCamera& camera, uint32_t view,
                        const std::vector<SurfacePoint>& points, double max_edge_m,
                        double min_facing_cosine, double bulge_fraction) {
  ViewSurface surface;
  surface.camera = &camera;
  std::vector<Corner> corners;
  for (const SurfacePoint& point : points) {
    if (!std::binary_search(point.views.begin(), point.views.end(), view)) continue;
    const double depth = camera.depth(point.X_W);
    if (!(depth > 0.0)) continue;
    corners.push_back({camera.projectIdeal(point.X_W), depth, point.depth_sigma_m, point.X_W});
  }
  if (corners.size() < 3) return surface;
  // One order whatever the points' order: Delaunay's choice among co-circular points and which of
  // two points on one pixel holds it follow the insertion order.
  std::sort(corners.begin(), corners.end(), [](const Corner& a, const Corner& b) {
    return std::tie(a.px.y(), a.px.x(), a.depth_m, a.sigma_m) <
           std::tie(b.px.y(), b.px.x(), b.depth_m, b.sigma_m);
  });
  Eigen::Vector2d lo = corners[0].px, hi = corners[0].px;
  for (const Corner& c : corners) lo = lo.cwiseMin(c.px), hi = hi.cwiseMax(c.px);
  surface.origin_px = lo.array().floor().cast<int>() - 1;
  const Eigen::Vector2i size = (hi.array().ceil().cast<int>() + 2) - surface.origin_px.array();
  surface.depth_m =
      cv::Mat(size.y(), size.x(), CV_32FC1, cv::Scalar(std::numeric_limits<float>::infinity()));
  surface.slack_m = cv::Mat::zeros(size.y(), size.x(), CV_32FC1);
  const cv::Rect bounds(surface.origin_px.x() - 1, surface.origin_px.y() - 1, size.x() + 2,
                        size.y() + 2);
  // Outliers first: a point whose depth departs from the median of its Delaunay neighbours' by
  // more than half a long edge (a wrong match among right ones) would break every triangle
  // around it.
  std::vector<std::vector<size_t>> neighbours;
  delaunayOf(corners, bounds, &neighbours);
  std::vector<Corner> inliers;
  for (size_t i = 0; i < corners.size(); ++i) {
    std::vector<double> depths;
    for (const size_t j : neighbours[i]) depths.push_back(corners[j].depth_m);
    if (depths.size() >= 3) {
      std::nth_element(depths.begin(), depths.begin() + depths.size() / 2, depths.end());
      if (std::abs(depths[depths.size() / 2] - corners[i].depth_m) > 0.5 * max_edge_m) continue;
    }
    inliers.push_back(corners[i]);
  }
  if (inliers.size() < 3) return surface;
  std::vector<std::vector<size_t>> unused;
  cv::Subdiv2D delaunay = delaunayOf(inliers, bounds, &unused);
  std::vector<cv::Vec6f> triangles;
  delaunay.getTriangleList(triangles);
  std::map<std::pair<float, float>, size_t> index_of;
  for (size_t i = 0; i < inliers.size(); ++i) {
    index_of.emplace(std::make_pair(static_cast<float>(inliers[i].px.x()),
                                    static_cast<float>(inliers[i].px.y())),
                     i);
  }
  for (const cv::Vec6f& t : triangles) {
    std::array<Corner, 3> triangle;
    bool real = true;
    for (int k = 0; k < 3 && real; ++k) {
      const auto found = index_of.find({t[2 * k], t[2 * k + 1]});
      real = found != index_of.end();
      if (real) triangle[k] = inliers[found->second];
    }
    if (!real) continue;  // a corner of Subdiv2D's outer triangle
    double longest_m = 0.0;
    for (int k = 0; k < 3; ++k) {
      longest_m = std::max(longest_m, (triangle[k].X_W - triangle[(k + 1) % 3].X_W).norm());
    }
    const bool short_edges = longest_m <= max_edge_m;
    const Eigen::Vector3d normal =
        (triangle[1].X_W - triangle[0].X_W).cross(triangle[2].X_W - triangle[0].X_W).normalized();
    const Eigen::Vector3d sight =
        ((triangle[0].X_W + triangle[1].X_W + triangle[2].X_W) / 3.0 - camera.centre())
            .normalized();
    if (short_edges && std::abs(normal.dot(sight)) >= min_facing_cosine) {
      rasterise(triangle, bulge_fraction * longest_m, &surface);
    }
  }
  return surface;
}

void checkViews(const std::vector<PinholeCamera>& cameras,
                const std::vector<SurfacePoint>& points) {
  for (const SurfacePoint& point : points) {
    for (const uint32_t view : point.views) {
      if (view >= cameras.size()) {
        throw std::invalid_argument("freeVoxels: a point seen by view " + std::to_string(view) +
                                    " of " + std::to_string(cameras.size()));
      }
    }
  }
}

}  // namespace

/// The state of one carving between its slices.
struct FreeSpaceCarving::State {
  FreeSpaceConfig config;
  HullCube cube;
  int threads = 1;
  std::vector<PinholeCamera> cameras;  ///< the surfaces point into these
  std::vector<SurfacePoint> points;    ///< each one's views sorted
  std::vector<ViewSurface> surfaces;
  uint32_t next_view = 0;  ///< the next view whose surface is made
  bool kept_done = false;
  std::unordered_set<uint64_t> kept;  ///< voxels near a surface point: never free
  std::vector<HullCell> leaves;       ///< the hull's occupied leaves at the start
  size_t next_leaf = 0;
  bool too_few_views = false;
};

FreeSpaceCarving::FreeSpaceCarving(const VisualHull& hull, std::vector<PinholeCamera> cameras,
                                   std::vector<SurfacePoint> points, const FreeSpaceConfig& config)
    : state_(std::make_unique<State>()) {
  validate(config);
  checkViews(cameras, points);
  State& s = *state_;
  s.config = config;
  s.cube = hull.cube();
  s.threads = hull.config().threads;
  s.cameras = std::move(cameras);
  s.points = std::move(points);
  for (SurfacePoint& point : s.points) std::sort(point.views.begin(), point.views.end());
  hull.forEachLeaf([&](const HullCell& cell) {
    if (cell.state != CellState::kOut) s.leaves.push_back(cell);
  });
}

FreeSpaceCarving::~FreeSpaceCarving() = default;

bool FreeSpaceCarving::done() const {
  const State& s = *state_;
  return s.too_few_views || s.next_leaf >= s.leaves.size();
}

bool FreeSpaceCarving::step(double budget_s, std::vector<Eigen::Vector3i>* free) {
  using Clock = std::chrono::steady_clock;
  const Clock::time_point start = Clock::now();
  const auto elapsed_s = [&] {
    return std::chrono::duration<double>(Clock::now() - start).count();
  };
  State& s = *state_;
  const double voxel_m = s.cube.resolution_m;
  const int cells = 1 << s.cube.depth;
  // Each view's surface, one view at a time.
  while (s.next_view < s.cameras.size()) {
    ViewSurface surface = viewSurface(
        s.cameras[s.next_view], s.next_view, s.points, s.config.max_edge_fraction * s.cube.edge_m(),
        std::cos(s.config.max_slant_deg * M_PI / 180.0), s.config.bulge_fraction);
    ++s.next_view;
    if (!surface.depth_m.empty()) s.surfaces.push_back(std::move(surface));
    if (s.next_view < s.cameras.size() && elapsed_s() >= budget_s) return false;
  }
  if (static_cast<int>(s.surfaces.size()) < s.config.min_views) s.too_few_views = true;
  if (done()) return true;
  if (!s.kept_done) {
    // The surface and a little around it stay.
    const int reach = static_cast<int>(std::ceil(s.config.keep_radius_voxels));
    const int side = 2 * reach + 1;
    for (const SurfacePoint& point : s.points) {
      const Eigen::Vector3d g = (point.X_W - s.cube.origin_W()) / voxel_m;
      const Eigen::Vector3i base = g.array().floor().cast<int>();
      for (int c = 0; c < side * side * side; ++c) {
        const Eigen::Vector3i voxel =
            base +
            Eigen::Vector3i(c % side - reach, c / side % side - reach, c / side / side - reach);
        if (detail::inCube(voxel, cells) &&
            ((voxel.cast<double>().array() + 0.5).matrix() - g).norm() <=
                s.config.keep_radius_voxels) {
          s.kept.insert(detail::voxelKey(voxel));
        }
      }
    }
    s.kept_done = true;
    if (elapsed_s() >= budget_s) return done();
  }
  // Every occupied finest voxel, a run of leaves at a time. The silhouettes settle the hull's
  // surface cells within a voxel already: those need two views (the lid a visual hull puts over a
  // cup's opening has them; the faces silhouettes see stay smooth).
  const int surface_views = std::max(s.config.min_views, 2);
  const double margin_m = s.config.stop_margin_voxels * voxel_m;
  const auto voxelsOf = [&](const HullCell& cell) {
    const size_t edge = size_t{1} << (s.cube.depth - cell.depth);
    return edge * edge * edge;
  };
  std::mutex free_mutex;
  double run_voxels = 4096.0, examined = 0.0;
  while (s.next_leaf < s.leaves.size()) {
    const size_t first = s.next_leaf;
    size_t end = first;
    double voxels = 0.0;
    while (end < s.leaves.size() && (voxels == 0.0 || voxels < run_voxels)) {
      voxels += static_cast<double>(voxelsOf(s.leaves[end++]));
    }
    detail::parallelFor(end - first, s.threads, [&](size_t i) {
      const HullCell& cell = s.leaves[first + i];
      const int edge = 1 << (s.cube.depth - cell.depth);
      std::vector<Eigen::Vector3i> found;
      for (int n = 0; n < edge * edge * edge; ++n) {
        const Eigen::Vector3i voxel =
            cell.index * edge + Eigen::Vector3i(n % edge, n / edge % edge, n / edge / edge);
        const Eigen::Vector3d centre_W =
            s.cube.origin_W() + (voxel.cast<double>().array() + 0.5).matrix() * voxel_m;
        const int needed = cell.state == CellState::kIn ? s.config.min_views : surface_views;
        int empty = 0;
        for (size_t v = 0; v < s.surfaces.size() && empty < needed; ++v) {
          empty += s.surfaces[v].seesEmpty(centre_W, margin_m) ? 1 : 0;
        }
        if (empty >= needed && s.kept.count(detail::voxelKey(voxel)) == 0) found.push_back(voxel);
      }
      if (found.empty()) return;
      std::lock_guard<std::mutex> lock(free_mutex);
      free->insert(free->end(), found.begin(), found.end());
    });
    s.next_leaf = end;
    examined += voxels;
    const double spent_s = elapsed_s();
    if (spent_s >= budget_s) break;
    // The next run: what the rest of the budget allows at the pace so far.
    run_voxels = spent_s > 0.0 ? std::min(4096.0 + (budget_s - spent_s) * examined / spent_s, 1e15)
                               : 2.0 * run_voxels;
  }
  return done();
}

std::vector<Eigen::Vector3i> freeVoxels(const VisualHull& hull,
                                        const std::vector<PinholeCamera>& cameras,
                                        const std::vector<SurfacePoint>& points,
                                        const FreeSpaceConfig& config) {
  FreeSpaceCarving carving(hull, cameras, points, config);
  std::vector<Eigen::Vector3i> free;
  carving.step(std::numeric_limits<double>::infinity(), &free);
  std::sort(free.begin(), free.end(), [](const Eigen::Vector3i& a, const Eigen::Vector3i& b) {
    return std::tie(a.z(), a.y(), a.x()) < std::tie(b.z(), b.y(), b.x());
  });
  return free;
}

}  // namespace sift_hull
