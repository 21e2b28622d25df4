#pragma once

// The densest window of a list of values (vote_ransac.cpp's vote for SIFT's rotations and scale
// ratios), on a line or on a circle.

#include <cstddef>
#include <vector>

namespace sift_hull {
namespace detail {

/// Among `candidates` (indices into values), the value that the most others lie within `half`
/// of (ties: the lowest index), and the candidates within `half` of it, in the candidates'
/// order; `*count`: how many lie within. `period` > 0: the values lie on a circle of that
/// period (angles); 0: on a line. The windows are centred on the values themselves, so shifting
/// every value shifts nothing else. `median`, when given: the median of the values within the
/// window (the lower of the middle two; on a circle, in [0, period); NaN without candidates).
std::vector<int> densestWindow(const std::vector<float>& values, const std::vector<int>& candidates,
                               double half, double period, size_t* count, float* median = nullptr);

}  // namespace detail
}  // namespace sift_hull
