#pragma once

#include <opencv2/core.hpp>
#include <vector>

namespace sift_hull {

/// A query's two nearest reference descriptors (Euclidean). -1 and infinity where there are fewer
/// than one or two references.
struct TwoNearest {
  int best = -1;
  int second = -1;
  float best_distance;    ///< L2 distance, not squared
  float second_distance;  ///< L2 distance, not squared
};

/// Exact nearest neighbours of every query among the references, in one pass.
struct NearestNeighbours {
  std::vector<TwoNearest> forward;  ///< per query (row of `queries`)
  /// Per reference, its nearest query's index (-1 when there are no queries): what the mutual
  /// (cross) check needs, from the same pass. Empty unless asked for.
  std::vector<int> reverse_nearest;
};

/// Exact nearest neighbours by matrix product: the squared distance ||q||^2 + ||r||^2 - 2 q.r of
/// every pair comes from one float32 matrix product (OpenBLAS sgemm) on blocks of queries and
/// references, so the memory is a few MB whatever the sizes. SIFT descriptors hold small
/// integers, for which every float32 sum is exact: the nearest neighbours are then those of an
/// exact brute force, up to ties. The distances reported are recomputed directly for the two kept.
/// `queries` and `references` are CV_32F with equal columns; throws std::invalid_argument
/// otherwise.
NearestNeighbours exactNearestNeighbours(const cv::Mat& queries, const cv::Mat& references,
                                         bool with_reverse);

}  // namespace sift_hull
