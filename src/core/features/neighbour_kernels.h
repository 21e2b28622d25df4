#pragma once

// Private to the features stage: the integer kernel behind exactNearestNeighbours. Descriptors
// that hold bytes (SIFT's do) take it on CPUs with AVX-512 VNNI; every other input takes the
// float32 matrix product (float32NearestNeighbours, nearest_neighbours.cpp).

#include <cstdint>
#include <opencv2/core.hpp>
#include <vector>

#include "sift_hull/features/nearest_neighbours.h"

namespace sift_hull {
namespace detail {

/// Widest descriptor the integer kernel takes: its int32 sums stay exact up to it.
constexpr int kMaxByteColumns = 1024;

/// True when this CPU (and its operating system) runs the AVX-512 VNNI kernel.
bool byteKernelAvailable();

/// Each query's two nearest references (-1 where there are fewer) with their squared distances
/// (exact integers; -1 with the index) and, with `with_reverse`, each reference's nearest query;
/// the lowest index first among equal distances.
struct ExactNeighbours {
  std::vector<int> best, second;
  std::vector<int32_t> best_squared, second_squared;
  std::vector<int> reverse;  ///< empty unless asked for
};

/// True when the kernel is available and the matrices are what it takes apart from their values:
/// CV_32F, two dimensions, equal columns from 1 to kMaxByteColumns, at least one row each.
bool byteKernelFits(const cv::Mat& queries, const cv::Mat& references);

/// True when every value of `descriptors` (CV_32F) is an integer in [0, 255].
bool holdsBytes(const cv::Mat& descriptors);

/// The exact two nearest neighbours by int8 dot products (AVX-512 VNNI). Returns false, having
/// done nothing, unless byteKernelFits and both matrices hold bytes (checked while packing them);
/// the caller then takes the float32 path.
bool byteNearestNeighbours(const cv::Mat& queries, const cv::Mat& references, bool with_reverse,
                           ExactNeighbours* out);

}  // namespace detail
}  // namespace sift_hull
