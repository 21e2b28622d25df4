#pragma once

// Private to the features stage: the integer kernel behind exactNearestNeighbours. Descriptors
// that hold bytes (SIFT's do) take it on CPUs with AVX-512 VNNI; every other input takes the
// float32 matrix product (float32NearestNeighbours, nearest_neighbours.cpp).

#include <opencv2/core.hpp>
#include <vector>

#include "sift_hull/features/nearest_neighbours.h"

namespace sift_hull {
namespace detail {

/// Widest descriptor the integer kernel takes: its int32 sums stay exact up to it.
constexpr int kMaxByteColumns = 1024;

/// True when this CPU (and its operating system) runs the AVX-512 VNNI kernel.
bool byteKernelAvailable();

/// Each query's two nearest references (-1 where there are fewer) and, with `with_reverse`, each
/// reference's nearest query: indices only, chosen on exact integer squared distances, the lowest
/// index first among equal distances.
struct NeighbourIndices {
  std::vector<int> best, second;
  std::vector<int> reverse;  ///< empty unless asked for
};

/// The exact two nearest neighbours by int8 dot products (AVX-512 VNNI). Returns false, having
/// done nothing, when the kernel is not available, a matrix is not CV_32F of at most
/// kMaxByteColumns columns, or a value is not an integer in [0, 255]; the caller then takes the
/// float32 path. `queries` and `references` have equal columns and at least one row each.
bool byteNearestNeighbours(const cv::Mat& queries, const cv::Mat& references, bool with_reverse,
                           NeighbourIndices* out);

/// True when `descriptors` is CV_32F, at most kMaxByteColumns wide, and every value is an
/// integer in [0, 255].
bool holdsBytes(const cv::Mat& descriptors);

}  // namespace detail
}  // namespace sift_hull
