#include "filters/densest_window.h"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <utility>

namespace sift_hull {
namespace detail {
namespace {

/// The float's bits as an unsigned key of the same order.
uint32_t orderedBits(float value) {
  uint32_t bits;
  std::memcpy(&bits, &value, sizeof bits);
  return (bits & 0x80000000u) ? ~bits : bits | 0x80000000u;
}

/// (value, index) of the candidates sorted by value, ties in the candidates' order: a stable
/// radix sort in four passes of 8 bits (candidates are at most a few thousand, so that larger
/// digits would spend more on their counts than on the keys).
std::vector<std::pair<float, int>> sortedByValue(const std::vector<float>& values,
                                                 const std::vector<int>& candidates) {
  const size_t n = candidates.size();
  if (n == 0) return {};
  std::vector<uint64_t> keys(n), scratch(n);
  for (size_t k = 0; k < n; ++k) {
    keys[k] = uint64_t(orderedBits(values[size_t(candidates[k])])) << 32 | uint32_t(k);
  }
  size_t count[4][257] = {};  // the four digits' counts, from one pass over the keys
  for (uint64_t key : keys) {
    for (int digit = 0; digit < 4; ++digit) ++count[digit][((key >> (32 + 8 * digit)) & 255u) + 1];
  }
  for (int digit = 0; digit < 4; ++digit) {
    const int shift = 32 + 8 * digit;
    size_t* start = count[digit];
    if (start[((keys[0] >> shift) & 255u) + 1] == n) continue;  // one digit for all: in order
    for (size_t d = 1; d < 257; ++d) start[d] += start[d - 1];
    for (uint64_t key : keys) scratch[start[(key >> shift) & 255u]++] = key;
    keys.swap(scratch);
  }
  std::vector<std::pair<float, int>> sorted(n);
  for (size_t k = 0; k < n; ++k) {
    const int c = candidates[size_t(keys[k] & 0xffffffffu)];
    sorted[k] = {values[size_t(c)], c};
  }
  return sorted;
}

/// |a - b|, on a circle of the period when it is positive.
double separation(double a, double b, double period) {
  const double d = std::abs(a - b);
  return period > 0.0 ? std::min(d, period - d) : d;
}

}  // namespace

std::vector<int> densestWindow(const std::vector<float>& values, const std::vector<int>& candidates,
                               double half, double period, size_t* count, float* median_out) {
  const std::vector<std::pair<float, int>> sorted = sortedByValue(values, candidates);
  const size_t n = sorted.size();
  std::vector<double> extended;  // circular: the values once below and once above the circle
  extended.reserve(period > 0.0 ? 3 * n : n);
  if (period > 0.0) {
    for (const auto& each : sorted) extended.push_back(each.first - period);
  }
  for (const auto& each : sorted) extended.push_back(each.first);
  if (period > 0.0) {
    for (const auto& each : sorted) extended.push_back(each.first + period);
  }
  size_t lo = 0, hi = 0, best = 0, best_lo = 0;
  int centre = -1;
  double centre_value = 0.0;
  for (size_t k = 0; k < n; ++k) {
    const double v = sorted[k].first;
    while (lo < extended.size() && extended[lo] < v - half) ++lo;
    while (hi < extended.size() && extended[hi] <= v + half) ++hi;
    const size_t within = std::min(hi - lo, n);
    if (within > best || (within == best && sorted[k].second < centre)) {
      best = within, centre = sorted[k].second, centre_value = v, best_lo = lo;
    }
  }
  *count = best;
  if (median_out) {  // the window's values lie in order from extended[best_lo]
    double median = n == 0 ? NAN : extended[best_lo + (best - 1) / 2];
    if (period > 0.0 && median < 0.0) median += period;
    if (period > 0.0 && median >= period) median -= period;
    *median_out = static_cast<float>(median);
  }
  std::vector<int> members;
  for (int i : candidates) {
    if (separation(values[i], centre_value, period) <= half) members.push_back(i);
  }
  return members;
}

}  // namespace detail
}  // namespace sift_hull
