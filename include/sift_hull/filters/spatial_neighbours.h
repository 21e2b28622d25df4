#pragma once

#include <cstddef>
#include <opencv2/core.hpp>
#include <vector>

namespace sift_hull {

/// The k nearest other points of every point, exactly (Euclidean; ties broken by the lower
/// index), from a uniform grid searched ring by ring: O(N k) for points spread over an image.
/// Row i of the result (k entries, nearest first) holds point i's neighbours, padded with -1 when
/// fewer than k other points exist. Points with a non-finite coordinate have no neighbours and are
/// no one's neighbour.
class SpatialNeighbours {
 public:
  SpatialNeighbours(const std::vector<cv::Point2f>& points, size_t k);
  size_t k() const { return k_; }
  const int* of(size_t i) const { return neighbours_.data() + i * k_; }

 private:
  size_t k_;
  std::vector<int> neighbours_;
};

}  // namespace sift_hull
