#include "sift_hull/filters/local_consistency.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <future>
#include <stdexcept>
#include <string>

#include "sift_hull/filters/gsc.h"
#include "sift_hull/filters/spatial_neighbours.h"
#include "sift_hull/limits.h"

namespace sift_hull {
namespace {

constexpr int kMaxNeighbours = 1024;

/// The matches whose points, sizes and angles are all finite, with both images' points and each
/// one's K nearest others among them.
struct LocalMatches {
  std::vector<size_t> index;  ///< into PutativeMatches::matches
  std::vector<cv::Point2f> left, right;
  std::vector<float> scale, angle_rad;  ///< size_right / size_left, angle_right - angle_left
  std::vector<float> left_angle_rad, right_angle_rad;
};

LocalMatches localMatches(const PutativeMatches& input) {
  LocalMatches local;
  for (size_t m = 0; m < input.matches.size(); ++m) {
    const cv::KeyPoint &l = input.left(m), &r = input.right(m);
    if (!input.hasFinitePositions(m) || !std::isfinite(l.angle) || !std::isfinite(r.angle) ||
        !(l.size > 0.f) || !(r.size > 0.f) || !std::isfinite(r.size / l.size)) {
      continue;
    }
    local.index.push_back(m);
    local.left.push_back(l.pt), local.right.push_back(r.pt);
    local.scale.push_back(r.size / l.size);
    local.left_angle_rad.push_back(static_cast<float>(l.angle * CV_PI / 180.0));
    local.right_angle_rad.push_back(static_cast<float>(r.angle * CV_PI / 180.0));
    local.angle_rad.push_back(local.right_angle_rad.back() - local.left_angle_rad.back());
  }
  return local;
}

/// Whether `to` lies within the tolerance of `from` + s R(a) `offset`.
bool lands(const cv::Point2f& from, const cv::Point2f& offset, float s, float c, float sn,
           const cv::Point2f& to, const LscConfig& config) {
  const float px = from.x + s * (c * offset.x - sn * offset.y);
  const float py = from.y + s * (sn * offset.x + c * offset.y);
  const float ex = to.x - px, ey = to.y - py;
  const float distance = s * std::sqrt(offset.x * offset.x + offset.y * offset.y);
  const float tolerance = static_cast<float>(config.max_relative_error) * distance +
                          static_cast<float>(config.min_tolerance_px);
  return ex * ex + ey * ey <= tolerance * tolerance;
}

/// Share of the neighbours (left image's nearest, then right image's) the match's similarity
/// predicts; NaN without neighbours.
double lscSupport(const LocalMatches& local, const SpatialNeighbours& in_left,
                  const SpatialNeighbours& in_right, size_t i, const LscConfig& config) {
  const float s = local.scale[i], c = std::cos(local.angle_rad[i]),
              sn = std::sin(local.angle_rad[i]);
  size_t agree = 0, looked = 0;
  for (size_t k = 0; k < in_left.k(); ++k) {
    const int n = in_left.of(i)[k];
    if (n < 0) break;
    ++looked;
    agree += lands(local.right[i], local.left[n] - local.left[i], s, c, sn, local.right[n], config);
  }
  for (size_t k = 0; k < in_right.k(); ++k) {
    const int n = in_right.of(i)[k];
    if (n < 0) break;
    ++looked;
    agree += lands(local.left[i], local.right[n] - local.right[i], 1.f / s, c, -sn, local.left[n],
                   config);
  }
  return looked == 0 ? NAN : double(agree) / looked;
}

/// The 8-sector histogram of the points around `centre`, polar angles from `axis_rad`.
GscHistogram sectorHistogram(const std::vector<cv::Point2f>& points, const std::vector<int>& set,
                             const cv::Point2f& centre, float axis_rad) {
  GscHistogram histogram{};
  size_t counted = 0;
  for (int n : set) {
    const cv::Point2f d = points[n] - centre;
    if (d.x == 0.f && d.y == 0.f) continue;
    double angle = std::atan2(d.y, d.x) - axis_rad;
    angle -= 2 * CV_PI * std::floor(angle / (2 * CV_PI));
    const int sector = std::min(kGscSectors - 1, int(angle / (CV_PI / 4)));
    histogram[sector] += 1.0, ++counted;
  }
  for (double& h : histogram) h = counted ? h / counted : 0.0;
  return histogram;
}

std::vector<int> unionOfNeighbours(const SpatialNeighbours& a, const SpatialNeighbours& b,
                                   size_t i) {
  std::vector<int> set;
  for (const SpatialNeighbours* each : {&a, &b}) {
    for (size_t k = 0; k < each->k(); ++k) {
      if (each->of(i)[k] >= 0) set.push_back(each->of(i)[k]);
    }
  }
  std::sort(set.begin(), set.end());
  set.erase(std::unique(set.begin(), set.end()), set.end());
  return set;
}

/// Both images' K nearest neighbours; the right image's on a second thread when there are enough
/// matches to pay for starting one and OpenCV may use more than one (cv::setNumThreads).
struct BothNeighbours {
  SpatialNeighbours left, right;
};

BothNeighbours neighboursInBoth(const LocalMatches& local, size_t k) {
  constexpr size_t kMinMatchesForThread = 1000;
  if (local.index.size() < kMinMatchesForThread || cv::getNumThreads() <= 1) {
    return {SpatialNeighbours(local.left, k), SpatialNeighbours(local.right, k)};
  }
  auto right = std::async(std::launch::async, [&] { return SpatialNeighbours(local.right, k); });
  SpatialNeighbours left(local.left, k);
  return {std::move(left), right.get()};
}

}  // namespace

FilterResult filterLsc(const PutativeMatches& input, const LscConfig& config) {
  validate(config);
  FilterResult result = FilterResult::keepingNone(input.matches.size());
  const LocalMatches local = localMatches(input);
  const BothNeighbours near = neighboursInBoth(local, static_cast<size_t>(config.neighbours));
  for (size_t i = 0; i < local.index.size(); ++i) {
    const double support = lscSupport(local, near.left, near.right, i, config);
    result.score[local.index[i]] = support;
    result.keep[local.index[i]] = support >= config.min_support;
  }
  return result;
}

FilterResult filterLocalGsc(const PutativeMatches& input, const LocalGscConfig& config) {
  validate(config);
  FilterResult result = FilterResult::keepingNone(input.matches.size());
  const LocalMatches local = localMatches(input);
  const BothNeighbours near = neighboursInBoth(local, static_cast<size_t>(config.neighbours));
  for (size_t i = 0; i < local.index.size(); ++i) {
    const std::vector<int> set = unionOfNeighbours(near.left, near.right, i);
    if (set.empty()) continue;
    const GscHistograms h{
        sectorHistogram(local.left, set, local.left[i], local.left_angle_rad[i]),
        sectorHistogram(local.right, set, local.right[i], local.right_angle_rad[i])};
    result.score[local.index[i]] = h.distance();
    result.keep[local.index[i]] = h.distance() <= config.max_histogram_distance;
  }
  return result;
}

}  // namespace sift_hull
