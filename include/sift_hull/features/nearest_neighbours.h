#pragma once

#include <opencv2/core.hpp>
#include <string>
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
/// every pair comes from a matrix product on blocks of queries and references, so the memory is a
/// few MB whatever the sizes, with the two nearest per query (and each reference's nearest query)
/// kept from the same pass. Two kernels, the same neighbours:
/// - descriptors whose values are all integers in [0, 255] (SIFT's are), at most 1,024 columns,
///   on a CPU with AVX-512 VNNI: int8 dot products with int32 sums, exact, ties included (the
///   lowest index first among equal distances);
/// - anything else: float32 through OpenBLAS sgemm (float32NearestNeighbours). For small
///   integers every float32 sum is exact: the nearest neighbours are those of an exact brute
///   force, up to ties.
/// The distances reported are recomputed directly for the two kept. `queries` and `references`
/// are CV_32F with equal columns; throws std::invalid_argument otherwise.
NearestNeighbours exactNearestNeighbours(const cv::Mat& queries, const cv::Mat& references,
                                         bool with_reverse);

/// exactNearestNeighbours through its float32 kernel (OpenBLAS sgemm) whatever the values: the
/// same checks, the same neighbours up to ties and rounding.
NearestNeighbours float32NearestNeighbours(const cv::Mat& queries, const cv::Mat& references,
                                           bool with_reverse);

/// The kernel exactNearestNeighbours takes for these descriptors on this CPU, for reports:
/// "int8 AVX-512 VNNI" or "float32 OpenBLAS sgemm (<OpenBLAS's core name> kernels)".
std::string exactNearestNeighboursKernel(const cv::Mat& queries, const cv::Mat& references);

}  // namespace sift_hull
