// Photo carving (sift_hull/mvs/photo_carving.h): the views' depth maps (depth_maps.cpp), the
// occupied finest voxels that several views see in front of their depth, and the silhouettes'
// check: a silhouette pixel whose line of sight, walked voxel by voxel through the hull, would meet
// only carved voxels keeps the one of them that the fewest views saw empty, with its neighbours.
//
// Cost: the sweep is views x neighbours x planes warps and box filters of the reduced images; the
// vote is occupied finest voxels x views projections; the check walks, per view, the pixels of
// the silhouette that carved voxels project onto, voxel by voxel over bit sets of the cube (three
// bits a voxel), each until its first occupied voxel that is neither free nor next to a free one.

#include <algorithm>
#include <chrono>
#include <cmath>
#include <limits>
#include <mutex>
#include <opencv2/imgproc.hpp>
#include <stdexcept>
#include <string>
#include <tuple>
#include <unordered_map>

#include "common/parallel.h"
#include "hull/voxel_key.h"
#include "mvs/mvs_internal.h"

namespace sift_hull {

template <>
const SettingTable<PhotoCarveConfig>& settingsOf<PhotoCarveConfig>() {
  static const SettingTable<PhotoCarveConfig> table = [] {
    using C = PhotoCarveConfig;
    SettingTable<C> t;
    t.add("photo_neighbours", &C::photo_neighbours, "views",
          "views each view's depth is measured against, the nearest by angle")
        .range(1, 16);
    t.add("photo_max_neighbour_angle_deg", &C::photo_max_neighbour_angle_deg, "deg",
          "neighbours seen at a larger angle from the view's line of sight are not used")
        .above(1.0, 180.0);
    t.add("photo_image_scale", &C::photo_image_scale, "",
          "the depth maps' largest resolution, as a share of the images' width and height")
        .above(0.0, 1.0);
    t.add("photo_voxel_px", &C::photo_voxel_px, "px",
          "each view's depth map is reduced until the finest voxel at the hull's centre spans "
          "this many of its pixels (at most photo_image_scale)")
        .above(0.0, 16.0);
    t.add("photo_patch_radius_px", &C::photo_patch_radius_px, "px",
          "patches of (2 r + 1)^2 pixels at the depth maps' resolution")
        .range(1, 10);
    t.add("photo_best_neighbours", &C::photo_best_neighbours, "views",
          "a depth's score is the mean NCC of this many best neighbours there")
        .range(1, 8);
    t.add("photo_min_ncc", &C::photo_min_ncc, "", "smallest score of a pixel's depth")
        .range(-1.0, 1.0);
    t.add("photo_min_patch_std", &C::photo_min_patch_std, "",
          "patches flatter than this (grey level standard deviation, 0..1) get no depth")
        .atLeast(0.0);
    t.add("photo_depth_planes", &C::photo_depth_planes, "planes",
          "depths swept per view over the hull's depth range")
        .range(2, 4096);
    t.add("photo_patch_match_rounds", &C::photo_patch_match_rounds, "rounds",
          "rounds of slanted-plane PatchMatch after the sweep (0: fronto-parallel depths only)")
        .range(0, 16);
    t.add("photo_consistency_voxels", &C::photo_consistency_voxels, "voxels",
          "a depth agrees with a neighbour's depth map within this many finest voxels")
        .above(0.0);
    t.add("photo_min_consistent_views", &C::photo_min_consistent_views, "views",
          "neighbours whose depth maps must agree with a pixel's depth to keep it")
        .range(0, 16);
    t.add("photo_margin_voxels", &C::photo_margin_voxels, "voxels",
          "a voxel is empty for a view this far in front of its depth")
        .atLeast(0.0);
    t.add("photo_min_views", &C::photo_min_views, "views",
          "views that must see a voxel empty, and more than see the surface there")
        .atLeast(1);
    return t;
  }();
  return table;
}

void validate(const PhotoCarveConfig& config) { checkSettings(config, "PhotoCarveConfig"); }

namespace {

using Clock = std::chrono::steady_clock;

double msSince(Clock::time_point start) {
  return std::chrono::duration<double, std::milli>(Clock::now() - start).count();
}

/// A voxel's votes: views that see it in front of their depth, and views that see the surface
/// there.
struct Votes {
  int empty = 0, surface = 0;
};

Votes votesAt(const Eigen::Vector3d& X_W, const std::vector<ViewDepth>& depths, double margin_m) {
  Votes votes;
  for (const ViewDepth& view : depths) {
    const double depth = view.camera.depth(X_W);
    if (!(depth > 0.0)) continue;
    const Eigen::Vector2d px = view.camera.projectIdeal(X_W);
    const long u = std::lround(px.x()), v = std::lround(px.y());
    if (u < 0 || v < 0 || u >= view.depth_m.cols || v >= view.depth_m.rows) continue;
    const float seen = view.depth_m.at<float>(static_cast<int>(v), static_cast<int>(u));
    if (std::isnan(seen)) continue;
    if (depth < seen - margin_m) {
      ++votes.empty;
    } else if (depth <= seen + margin_m) {
      ++votes.surface;
    }
  }
  return votes;
}

/// The free voxels and their votes, for the silhouettes' check: a bit per voxel of the cube for
/// "occupied" (in an occupied leaf), "free" and "one of its 26 neighbours is free" (then a corner
/// of it touches free space, where the mesh's free-space field and carveFree's closure cut into
/// it), 3 2^(3 depth - 3) bytes (6 MB at depth 8, 48 MB at depth 9), so that the walks test bits;
/// the votes in a hash map.
class FreeSet {
 public:
  FreeSet(int depth, const std::vector<HullCell>& occupied,
          const std::vector<std::pair<Eigen::Vector3i, int>>& free)
      : depth_(depth),
        cells_(1 << depth),
        free_bits_((size_t{1} << (3 * depth)) / 64 + 1, 0),
        touch_bits_(free_bits_.size(), 0),
        occupied_bits_(free_bits_.size(), 0) {
    for (const HullCell& cell : occupied) {
      const int edge = 1 << (depth - cell.depth);
      const Eigen::Vector3i first = cell.index * edge;
      for (int z = 0; z < edge; ++z) {
        for (int y = 0; y < edge; ++y) {
          for (int x = 0; x < edge; ++x) {
            set(&occupied_bits_, first + Eigen::Vector3i(x, y, z), true);
          }
        }
      }
    }
    for (const auto& [voxel, votes] : free) {
      if (!detail::inCube(voxel, cells_)) continue;
      votes_.emplace(detail::voxelKey(voxel), votes);
      set(&free_bits_, voxel, true);
    }
    for (const auto& [voxel, votes] : free) {
      for (int n = 0; n < 27; ++n) {
        const Eigen::Vector3i other = voxel + offset(n);
        if (n != 13 && detail::inCube(other, cells_)) set(&touch_bits_, other, true);
      }
    }
  }

  bool empty() const { return votes_.empty(); }
  const std::unordered_map<uint64_t, int>& votes() const { return votes_; }
  bool isFree(const Eigen::Vector3i& voxel) const { return test(free_bits_, voxel); }
  /// In an occupied leaf of the hull (free or not).
  bool isOccupied(const Eigen::Vector3i& voxel) const { return test(occupied_bits_, voxel); }
  bool touchesFree(const Eigen::Vector3i& voxel) const { return test(touch_bits_, voxel); }
  int votesOf(const Eigen::Vector3i& voxel) const { return votes_.at(detail::voxelKey(voxel)); }

  /// Makes a voxel occupied again: 1 if it was free, else 0.
  size_t erase(const Eigen::Vector3i& voxel) {
    if (!detail::inCube(voxel, cells_) || !isFree(voxel)) return 0;
    votes_.erase(detail::voxelKey(voxel));
    set(&free_bits_, voxel, false);
    for (int n = 0; n < 27; ++n) {  // its neighbours may touch free voxels no longer
      const Eigen::Vector3i other = voxel + offset(n);
      if (n == 13 || !detail::inCube(other, cells_)) continue;
      bool touches = false;
      for (int m = 0; m < 27 && !touches; ++m) {
        const Eigen::Vector3i next = other + offset(m);
        touches = m != 13 && detail::inCube(next, cells_) && isFree(next);
      }
      set(&touch_bits_, other, touches);
    }
    return 1;
  }

 private:
  static Eigen::Vector3i offset(int n) { return {n % 3 - 1, n / 3 % 3 - 1, n / 9 - 1}; }
  size_t bit(const Eigen::Vector3i& voxel) const {
    return (static_cast<size_t>(voxel.z()) << (2 * depth_)) |
           (static_cast<size_t>(voxel.y()) << depth_) | static_cast<size_t>(voxel.x());
  }
  bool test(const std::vector<uint64_t>& bits, const Eigen::Vector3i& voxel) const {
    const size_t b = bit(voxel);
    return (bits[b >> 6] >> (b & 63)) & 1u;
  }
  void set(std::vector<uint64_t>* bits, const Eigen::Vector3i& voxel, bool on) const {
    const size_t b = bit(voxel);
    if (on) {
      (*bits)[b >> 6] |= uint64_t{1} << (b & 63);
    } else {
      (*bits)[b >> 6] &= ~(uint64_t{1} << (b & 63));
    }
  }

  int depth_, cells_;
  std::vector<uint64_t> free_bits_, touch_bits_, occupied_bits_;
  std::unordered_map<uint64_t, int> votes_;
};

/// The voxel a silhouette pixel's line of sight needs kept with its 26 neighbours, or no key (~0)
/// when its walk through the cube meets an occupied voxel that is neither free nor next to a free
/// one (or meets no voxel of the hull): the weakest free voxel on the way, else the first occupied
/// voxel next to a free one. The walk goes voxel by voxel (Amanatides and Woo) over the bits.
uint64_t neededOnRay(const HullCube& cube, const Eigen::Vector3d& origin_W,
                     const Eigen::Vector3d& direction, const FreeSet& free) {
  constexpr uint64_t kNone = ~uint64_t{0};
  const double voxel_m = cube.resolution_m;
  const int cells = 1 << cube.depth;
  const Eigen::Vector3d lo = cube.origin_W(), hi = lo + Eigen::Vector3d::Constant(cube.edge_m());
  double t0 = 0.0, t1 = std::numeric_limits<double>::infinity();
  for (int a = 0; a < 3; ++a) {  // the ray's span inside the cube
    if (direction[a] == 0.0) {
      if (origin_W[a] < lo[a] || origin_W[a] > hi[a]) return kNone;
      continue;
    }
    double near = (lo[a] - origin_W[a]) / direction[a], far = (hi[a] - origin_W[a]) / direction[a];
    if (near > far) std::swap(near, far);
    t0 = std::max(t0, near), t1 = std::min(t1, far);
  }
  if (!(t0 < t1)) return kNone;
  const Eigen::Vector3d X = origin_W + direction * (t0 + 1e-6 * voxel_m);
  Eigen::Vector3i at =
      ((X - lo) / voxel_m).array().floor().cast<int>().max(0).min(cells - 1).matrix();
  Eigen::Vector3i step;
  Eigen::Vector3d next_t, delta_t;
  for (int a = 0; a < 3; ++a) {
    step[a] = direction[a] > 0.0 ? 1 : -1;
    const double boundary = (at[a] + (step[a] > 0 ? 1 : 0)) * voxel_m + lo[a];
    delta_t[a] = direction[a] == 0.0 ? std::numeric_limits<double>::infinity()
                                     : voxel_m / std::abs(direction[a]);
    next_t[a] = direction[a] == 0.0 ? std::numeric_limits<double>::infinity()
                                    : (boundary - origin_W[a]) / direction[a];
  }
  uint64_t weakest = kNone, first_touching = kNone;
  int weakest_votes = std::numeric_limits<int>::max();
  while (detail::inCube(at, cells)) {
    if (free.isOccupied(at)) {
      if (free.isFree(at)) {
        const int votes = free.votesOf(at);
        if (votes <= weakest_votes) weakest = detail::voxelKey(at), weakest_votes = votes;
      } else if (!free.touchesFree(at)) {
        return kNone;
      } else if (first_touching == kNone) {
        first_touching = detail::voxelKey(at);
      }
    }
    int a = 0;
    if (next_t[1] < next_t[a]) a = 1;
    if (next_t[2] < next_t[a]) a = 2;
    if (next_t[a] >= t1) break;
    at[a] += step[a];
    next_t[a] += delta_t[a];
  }
  return weakest != kNone ? weakest : first_touching;
}

}  // namespace

PhotoCarveResult photoCarve(const VisualHull& hull, const PhotoViews& views,
                            const PhotoCarveConfig& config) {
  validate(config);
  const size_t count = views.cameras.size();
  if (count < 2) throw std::invalid_argument("photo carving needs two views at least");
  const HullCube& cube = hull.cube();
  const double voxel_m = cube.resolution_m;
  const int threads = hull.config().threads;
  PhotoCarveResult result;
  Clock::time_point start = Clock::now();
  std::vector<detail::ReducedView> reduced(count);
  std::vector<cv::Mat> masks(count);
  const Eigen::Vector3d centre_W = cube.origin_W() + Eigen::Vector3d::Constant(cube.edge_m() / 2);
  result.scale_min = config.photo_image_scale;
  for (uint32_t v = 0; v < count; ++v) {
    masks[v] = views.mask(v);
    const cv::Mat image = views.image(v);
    const PinholeCamera& camera = views.cameras[v];
    if (image.empty() || image.size() != masks[v].size()) {
      throw std::invalid_argument("photo carving: view " + std::to_string(v) +
                                  ": its image and silhouette differ in size");
    }
    const double scale = detail::depthMapScale(camera, centre_W, voxel_m, config);
    result.scale_min = std::min(result.scale_min, scale);
    result.scale_max = std::max(result.scale_max, scale);
    reduced[v] = detail::reducedView(camera, image, masks[v], scale, config.photo_patch_radius_px);
  }
  const std::vector<HullCell> occupied = detail::occupiedLeaves(hull);
  const std::vector<std::vector<uint32_t>> neighbours = detail::chooseNeighbours(
      views.cameras, centre_W, config.photo_neighbours, config.photo_max_neighbour_angle_deg);
  result.depths.resize(count);
  std::vector<size_t> sweeps(count, 0);
  detail::parallelFor(count, threads, [&](size_t v) {
    ViewDepth& depth = result.depths[v];
    depth.camera = reduced[v].camera;
    depth.neighbours = neighbours[v];
    if (neighbours[v].empty()) {
      depth.depth_m = cv::Mat(reduced[v].grey.size(), CV_32FC1, cv::Scalar(NAN));
      depth.ncc = depth.depth_m.clone();
      return;
    }
    const detail::DepthRange range =
        detail::hullDepthRange(occupied, cube, depth.camera, reduced[v].grey.size());
    detail::sweepDepth(reduced, static_cast<uint32_t>(v), neighbours[v], range, config, voxel_m,
                       &depth.depth_m, &depth.ncc, &sweeps[v]);
    detail::patchMatchDepth(reduced, static_cast<uint32_t>(v), neighbours[v], range, config,
                            voxel_m, &depth.depth_m, &depth.ncc);
    const cv::Mat weak = ~(depth.ncc >= config.photo_min_ncc);  // NaN scores compare false
    depth.depth_m.setTo(NAN, weak);
    depth.ncc.setTo(NAN, weak);
  });
  for (size_t v = 0; v < count; ++v) {
    result.sweeps += sweeps[v];
    result.depth_pixels +=
        static_cast<size_t>(cv::countNonZero(result.depths[v].depth_m == result.depths[v].depth_m));
  }
  result.depth_ms = msSince(start);

  start = Clock::now();
  std::vector<cv::Mat> kept(count);
  detail::parallelFor(count, threads, [&](size_t v) {
    kept[v] = detail::consistentDepth(result.depths, static_cast<uint32_t>(v), config, voxel_m);
  });
  for (size_t v = 0; v < count; ++v) {
    result.depths[v].depth_m = kept[v];
    result.consistent_pixels += static_cast<size_t>(cv::countNonZero(kept[v] == kept[v]));
  }
  result.consistency_ms = msSince(start);

  // Votes of every occupied finest voxel.
  start = Clock::now();
  const double margin_m = config.photo_margin_voxels * voxel_m;
  std::vector<std::pair<Eigen::Vector3i, int>> free;
  std::mutex free_mutex;
  detail::parallelFor(occupied.size(), threads, [&](size_t i) {
    const HullCell& cell = occupied[i];
    const int edge = 1 << (cube.depth - cell.depth);
    std::vector<std::pair<Eigen::Vector3i, int>> found;
    for (int n = 0; n < edge * edge * edge; ++n) {
      const Eigen::Vector3i voxel =
          cell.index * edge + Eigen::Vector3i(n % edge, n / edge % edge, n / edge / edge);
      const Votes votes = votesAt(detail::voxelCentre(cube, voxel), result.depths, margin_m);
      if (votes.empty >= config.photo_min_views && votes.empty > votes.surface) {
        found.emplace_back(voxel, votes.empty);
      }
    }
    if (found.empty()) return;
    std::lock_guard<std::mutex> lock(free_mutex);
    free.insert(free.end(), found.begin(), found.end());
  });
  result.voting_ms = msSince(start);

  // The silhouettes' check, view by view in their order.
  start = Clock::now();
  FreeSet free_set(cube.depth, occupied, free);
  for (uint32_t v = 0; v < count && !free_set.empty(); ++v) {
    const PinholeCamera& camera = views.cameras[v];
    const cv::Mat& mask = masks[v];
    // The pixels free voxels project onto, grown by the largest reach of a voxel and its
    // neighbours (whose corners it touches: two and a half voxels) in this view.
    cv::Mat at_risk(mask.size(), CV_8UC1, cv::Scalar(0));
    const double focal = std::max(camera.K()(0, 0), camera.K()(1, 1));
    double reach = 0.0;
    for (const auto& [key, votes] : free_set.votes()) {
      const Eigen::Vector3d X_W = detail::voxelCentre(cube, detail::voxelOfKey(key));
      const double depth = camera.depth(X_W);
      if (!(depth > 0.0)) continue;
      const Eigen::Vector2d px = camera.project(X_W);
      const double r = 2.6 * voxel_m * focal / depth + 1.5;
      // A voxel whose square of reach meets the image marks the pixel nearest its centre.
      if (!(px.x() + r >= 0.0 && px.y() + r >= 0.0 && px.x() - r <= mask.cols - 1 &&
            px.y() - r <= mask.rows - 1)) {
        continue;
      }
      reach = std::max(reach, r);
      const int u = static_cast<int>(std::clamp(std::lround(px.x()), 0L, mask.cols - 1L));
      const int v = static_cast<int>(std::clamp(std::lround(px.y()), 0L, mask.rows - 1L));
      at_risk.at<uint8_t>(v, u) = 255;
    }
    if (reach > 0.0) {
      // Beyond the image the clamped centre stands in for the voxel: the reach from it covers
      // at least what the voxel's square covers inside the image.
      const int side = 2 * static_cast<int>(std::ceil(reach)) + 1;
      cv::dilate(at_risk, at_risk, cv::getStructuringElement(cv::MORPH_RECT, {side, side}));
    }
    std::vector<std::vector<uint64_t>> needed(static_cast<size_t>(mask.rows));
    const Eigen::Vector3d origin_W = camera.centre();
    detail::parallelFor(static_cast<size_t>(mask.rows), threads, [&](size_t row) {
      const int r = static_cast<int>(row);
      for (int u = 0; u < mask.cols; ++u) {
        if (!mask.at<uint8_t>(r, u) || !at_risk.at<uint8_t>(r, u)) continue;
        const Eigen::Vector3d direction = camera.rayDirection(Eigen::Vector2d(u, r));
        if (!direction.allFinite()) continue;
        const uint64_t key = neededOnRay(cube, origin_W, direction, free_set);
        if (key != ~uint64_t{0}) needed[row].push_back(key);
      }
    });
    for (const std::vector<uint64_t>& keys : needed) {
      for (uint64_t key : keys) {
        // With its 26 neighbours: carveFree's closure frees a voxel all of whose corners touch
        // free voxels, and the mesh grows the free space by a quarter of a voxel.
        const Eigen::Vector3i centre = detail::voxelOfKey(key);
        for (int n = 0; n < 27; ++n) {
          const Eigen::Vector3i voxel =
              centre + Eigen::Vector3i(n % 3 - 1, n / 3 % 3 - 1, n / 9 - 1);
          result.restored_voxels += free_set.erase(voxel);
        }
      }
    }
  }
  for (const auto& [voxel, votes] : free) {
    if (free_set.isFree(voxel)) result.free_voxels.push_back(voxel);
  }
  std::sort(result.free_voxels.begin(), result.free_voxels.end(),
            [](const Eigen::Vector3i& a, const Eigen::Vector3i& b) {
              return std::tie(a.z(), a.y(), a.x()) < std::tie(b.z(), b.y(), b.x());
            });
  result.silhouettes_ms = msSince(start);
  return result;
}

}  // namespace sift_hull
