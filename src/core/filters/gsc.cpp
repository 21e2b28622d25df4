// The global scale-invariant constraint (GSC): for each putative match, the polar angles of all
// other matched keypoints around it, measured from the keypoint's main orientation (the paper's
// eq. 11), histogrammed into 8 sectors of 45 degrees in the left and in the right image. A correct
// match sees the same layout of the other matches in both images, whatever their rotation and
// scale; a mismatch sees two unrelated layouts. The histograms are normalised to sum to 1 and
// compared by Euclidean distance.
//
// Sector of a point (no atan2): with (a, b) its coordinates along the keypoint's orientation and
// across it (rounded to float, computed with fused multiply-adds as below), the signs of a, b, b -
// a and b + a tell the 45-degree sector. Sector k holds polar angles in [45k, 45k + 45) degrees
// above the polar axis (b > 0) and their mirror images below it; a point exactly on a border line
// counts in the upper half (b = 0) or in the sector farther from the polar axis direction (other
// borders). Points coincident with the keypoint have no polar angle and are left out.

#include "sift_hull/filters/gsc.h"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <random>
#include <thread>

#include "common/parallel.h"

namespace sift_hull {
namespace {

// Label of a point: bit 0 "a <= 0", bit 1 "b < 0", bit 2 "(b < a) != (b + a <= 0)". The labels
// are a permutation of the sectors.
constexpr int kSectorOfLabel[kGscSectors] = {1, 2, 6, 5, 0, 3, 7, 4};
// Label of a point coincident with the keypoint (a = b = 0).
[[maybe_unused]] constexpr int kCoincidentLabel = 5;
// Label of the NaN padding (every comparison false).
constexpr int kPaddingLabel = 0;
// Points per vector lane group the arrays are padded to, and per block of byte-wide counters
// (each counter holds at most 255).
constexpr size_t kPadding = 16;
constexpr size_t kBlock = 240;

using LabelCounts = std::array<uint32_t, kGscSectors>;

/// The keypoints of the valid matches in one image, as arrays padded with NaN to kPadding.
struct PolarPoints {
  std::vector<float> x, y, cos_angle, sin_angle;
  size_t count = 0;
  std::vector<uint32_t> coincident;  ///< per point, how many points share its position (>= 1)
};

/// cos and sin of an angle in degrees, exact at multiples of 90 degrees.
void unitDirection(float angle_deg, float* c, float* s) {
  const double reduced = std::fmod(static_cast<double>(angle_deg), 360.0);
  if (std::fmod(reduced, 90.0) == 0.0) {
    const int quarter = static_cast<int>(std::lround(reduced / 90.0) + 4) % 4;
    constexpr float kCos[4] = {1.f, 0.f, -1.f, 0.f}, kSin[4] = {0.f, 1.f, 0.f, -1.f};
    *c = kCos[quarter];
    *s = kSin[quarter];
    return;
  }
  const double radians = reduced * M_PI / 180.0;
  *c = static_cast<float>(std::cos(radians));
  *s = static_cast<float>(std::sin(radians));
}

/// Label counts of all points around point (xi, yi) with orientation (c, s); n is a multiple of
/// kPadding. Byte-wide counters per label, 4 to a 32-bit word, let the loop vectorise.
__attribute__((target_clones("arch=x86-64-v4", "arch=x86-64-v3", "default"))) void countLabels(
    const float* x, const float* y, size_t n, float xi, float yi, float c, float s,
    LabelCounts* counts) {
  const float offset_a = std::fma(xi, c, yi * s);
  const float offset_b = std::fma(yi, c, -(xi * s));
  counts->fill(0);
  for (size_t start = 0; start < n; start += kBlock) {
    const size_t end = std::min(n, start + kBlock);
    uint32_t low = 0, high = 0;
    for (size_t j = start; j < end; ++j) {
      const float a = std::fma(x[j], c, std::fma(y[j], s, -offset_a));
      const float b = std::fma(y[j], c, std::fma(x[j], -s, -offset_b));
      const uint32_t shift = (a <= 0.f ? 8u : 0u) + (b < 0.f ? 16u : 0u);
      const bool upper_labels = (b < a) != (b + a <= 0.f);
      const uint32_t increment = 1u << shift;
      low += upper_labels ? 0u : increment;
      high += upper_labels ? increment : 0u;
    }
    for (int k = 0; k < 4; ++k) {
      (*counts)[k] += (low >> (8 * k)) & 255u;
      (*counts)[4 + k] += (high >> (8 * k)) & 255u;
    }
  }
}

/// The label a point at the keypoint's own position gets from countLabels' arithmetic: the
/// offsets are rounded, so it need not be kCoincidentLabel.
int labelOfKeypoint(float xi, float yi, float c, float s) {
  const float offset_a = std::fma(xi, c, yi * s);
  const float offset_b = std::fma(yi, c, -(xi * s));
  const float a = std::fma(xi, c, std::fma(yi, s, -offset_a));
  const float b = std::fma(yi, c, std::fma(xi, -s, -offset_b));
  return (a <= 0.f ? 1 : 0) + (b < 0.f ? 2 : 0) + ((b < a) != (b + a <= 0.f) ? 4 : 0);
}

/// For each point, how many points (itself included) have exactly its coordinates.
std::vector<uint32_t> coincidentCounts(const std::vector<float>& x, const std::vector<float>& y,
                                       size_t count) {
  std::vector<size_t> order(count);
  for (size_t i = 0; i < count; ++i) order[i] = i;
  const auto before = [&](size_t p, size_t q) {
    return std::tie(x[p], y[p]) < std::tie(x[q], y[q]);
  };
  std::sort(order.begin(), order.end(), before);
  std::vector<uint32_t> result(count);
  for (size_t first = 0; first < count;) {
    size_t last = first + 1;
    while (last < count && x[order[last]] == x[order[first]] && y[order[last]] == y[order[first]]) {
      ++last;
    }
    for (size_t k = first; k < last; ++k) result[order[k]] = static_cast<uint32_t>(last - first);
    first = last;
  }
  return result;
}

PolarPoints polarPoints(const std::vector<const cv::KeyPoint*>& keypoints,
                        bool with_coincident = true) {
  PolarPoints points;
  points.count = keypoints.size();
  const size_t padded = (points.count + kPadding - 1) / kPadding * kPadding;
  points.x.assign(padded, NAN);
  points.y.assign(padded, NAN);
  points.cos_angle.resize(points.count);
  points.sin_angle.resize(points.count);
  for (size_t i = 0; i < points.count; ++i) {
    points.x[i] = keypoints[i]->pt.x;
    points.y[i] = keypoints[i]->pt.y;
    unitDirection(keypoints[i]->angle, &points.cos_angle[i], &points.sin_angle[i]);
  }
  if (with_coincident) points.coincident = coincidentCounts(points.x, points.y, points.count);
  return points;
}

/// The normalised sector histogram of all other points around point i (the paper's histogram of
/// eq. 11's polar angles, 8 bins of 45 degrees).
GscHistogram histogramAround(const PolarPoints& points, size_t i) {
  const float xi = points.x[i], yi = points.y[i];
  const float c = points.cos_angle[i], s = points.sin_angle[i];
  LabelCounts counts;
  countLabels(points.x.data(), points.y.data(), points.x.size(), xi, yi, c, s, &counts);
  counts[kPaddingLabel] -= static_cast<uint32_t>(points.x.size() - points.count);
  counts[labelOfKeypoint(xi, yi, c, s)] -= points.coincident[i];
  const uint32_t others = static_cast<uint32_t>(points.count) - points.coincident[i];
  GscHistogram histogram{};
  if (others == 0) return histogram;
  for (int label = 0; label < kGscSectors; ++label) {
    histogram[kSectorOfLabel[label]] = static_cast<double>(counts[label]) / others;
  }
  return histogram;
}

double histogramDistance(const GscHistogram& left, const GscHistogram& right) {
  double sum = 0.0;
  for (int k = 0; k < kGscSectors; ++k) sum += (left[k] - right[k]) * (left[k] - right[k]);
  return std::sqrt(sum);
}

/// Indices of the matches whose keypoints are all finite; only these take part.
std::vector<size_t> validMatches(const PutativeMatches& input) {
  std::vector<size_t> valid;
  for (size_t m = 0; m < input.matches.size(); ++m) {
    const bool finite_angles =
        std::isfinite(input.left(m).angle) && std::isfinite(input.right(m).angle);
    if (input.hasFinitePositions(m) && finite_angles) valid.push_back(m);
  }
  return valid;
}

/// The given matches' left and right points (with their coincident counts unless told not to).
std::pair<PolarPoints, PolarPoints> polarPointsOf(const PutativeMatches& input,
                                                  const std::vector<size_t>& matches,
                                                  bool with_coincident = true) {
  std::vector<const cv::KeyPoint*> left, right;
  for (size_t m : matches) {
    left.push_back(&input.left(m));
    right.push_back(&input.right(m));
  }
  return {polarPoints(left, with_coincident), polarPoints(right, with_coincident)};
}

/// Below this many valid matches one thread is faster than starting more.
constexpr size_t kMinMatchesPerThread = 600;

int threadCount(int requested, size_t matches) {
  const int hardware = std::max(1u, std::thread::hardware_concurrency());
  const int wanted = requested > 0 ? requested : hardware;
  const size_t useful = std::max<size_t>(1, matches / kMinMatchesPerThread);
  return static_cast<int>(std::min<size_t>(wanted, useful));
}

/// Histogram distance of every valid match, on `threads` threads.
std::vector<double> histogramDistances(const PolarPoints& left, const PolarPoints& right,
                                       int threads) {
  std::vector<double> distances(left.count);
  detail::parallelFor(left.count, threads, [&](size_t i) {
    distances[i] = histogramDistance(histogramAround(left, i), histogramAround(right, i));
  });
  return distances;
}

/// The histogram around an arbitrary centre over the points of `sample` (its padding and the
/// sample points at the centre itself, `coincident` of them, left out).
GscHistogram histogramOver(const PolarPoints& sample, float xi, float yi, float c, float s,
                           uint32_t coincident) {
  LabelCounts counts;
  countLabels(sample.x.data(), sample.y.data(), sample.x.size(), xi, yi, c, s, &counts);
  counts[kPaddingLabel] -= static_cast<uint32_t>(sample.x.size() - sample.count);
  counts[labelOfKeypoint(xi, yi, c, s)] -= coincident;
  const uint32_t others = static_cast<uint32_t>(sample.count) - coincident;
  GscHistogram histogram{};
  if (others == 0) return histogram;
  for (int label = 0; label < kGscSectors; ++label) {
    histogram[kSectorOfLabel[label]] = static_cast<double>(counts[label]) / others;
  }
  return histogram;
}

/// How many points of `sample` sit exactly at (x, y); the NaN padding never does. Branch-free
/// so that it vectorises like countLabels.
__attribute__((target_clones("arch=x86-64-v4", "arch=x86-64-v3", "default"))) uint32_t
coincidentInSample(const PolarPoints& sample, float x, float y) {
  const float* sx = sample.x.data();
  const float* sy = sample.y.data();
  uint32_t count = 0;
  for (size_t j = 0; j < sample.x.size(); ++j) {
    count += static_cast<uint32_t>(sx[j] == x) & static_cast<uint32_t>(sy[j] == y);
  }
  return count;
}

/// The histogram around a keypoint over the sample's points.
GscHistogram histogramOfKeypoint(const PolarPoints& sample, const cv::KeyPoint& keypoint) {
  float c = 0.f, s = 0.f;
  unitDirection(keypoint.angle, &c, &s);
  const float x = keypoint.pt.x, y = keypoint.pt.y;
  return histogramOver(sample, x, y, c, s, coincidentInSample(sample, x, y));
}

/// The sampled filter: every match's histograms over the same M sampled matches left and right.
/// Only the sample is prepared up front; each match's own work (its direction, the sample points
/// at its position, both histograms) runs on the threads.
std::vector<double> sampledDistances(const PutativeMatches& input, const std::vector<size_t>& valid,
                                     size_t support, int threads) {
  std::vector<size_t> chosen(valid);
  std::shuffle(chosen.begin(), chosen.end(), std::mt19937(1));  // fixed: the same every call
  chosen.resize(support);
  // The sample's own coincident counts are not needed: coincidentInSample counts per match.
  const std::pair<PolarPoints, PolarPoints> sample = polarPointsOf(input, chosen, false);
  std::vector<double> distances(valid.size());
  detail::parallelFor(valid.size(), threads, [&](size_t i) {
    distances[i] = histogramDistance(histogramOfKeypoint(sample.first, input.left(valid[i])),
                                     histogramOfKeypoint(sample.second, input.right(valid[i])));
  });
  return distances;
}

}  // namespace

double GscHistograms::distance() const { return histogramDistance(left, right); }

FilterResult filterGsc(const PutativeMatches& input, const GscConfig& config) {
  FilterResult result = FilterResult::keepingNone(input.matches.size());
  const std::vector<size_t> valid = validMatches(input);
  const int threads = threadCount(config.threads, valid.size());
  const size_t support = static_cast<size_t>(std::max(config.max_support, 0));
  std::vector<double> distances;
  if (support > 0 && support < valid.size()) {
    distances = sampledDistances(input, valid, support, threads);
  } else {
    const auto [left, right] = polarPointsOf(input, valid);
    distances = histogramDistances(left, right, threads);
  }
  for (size_t v = 0; v < valid.size(); ++v) {
    result.score[valid[v]] = distances[v];
    result.keep[valid[v]] = distances[v] <= config.max_histogram_distance;
  }
  return result;
}

GscHistograms gscHistograms(const PutativeMatches& input, size_t match) {
  if (match >= input.matches.size()) throw std::out_of_range("gscHistograms: no such match");
  const std::vector<size_t> valid = validMatches(input);
  const auto position = std::find(valid.begin(), valid.end(), match);
  if (position == valid.end()) return GscHistograms{};
  const auto [left, right] = polarPointsOf(input, valid);
  const size_t i = static_cast<size_t>(position - valid.begin());
  return {histogramAround(left, i), histogramAround(right, i)};
}

}  // namespace sift_hull
