#pragma once

#include <cstdint>
#include <opencv2/core.hpp>
#include <vector>

#include "sift_hull/hull/bounding_box.h"

namespace sift_hull {

/// A binary silhouette stored as runs of inside pixels, row by row: a few bytes per row where a
/// cv::Mat holds one per pixel. Lossless: decode() gives back `mask != 0` as 0 / 255.
class RunLengthMask {
 public:
  RunLengthMask() = default;
  /// `mask`: CV_8UC1, non-zero inside. Throws std::invalid_argument for another type or an
  /// empty mask.
  explicit RunLengthMask(const cv::Mat& mask);

  cv::Size size() const { return size_; }
  bool empty() const { return size_.area() == 0; }
  /// Whether pixel (u, v) is inside; false outside the image.
  bool at(int u_px, int v_px) const;
  /// The mask, CV_8UC1, 255 inside and 0 outside.
  cv::Mat decode() const;
  /// Writes rows [row_begin, row_begin + out->rows) and columns [col_begin, col_begin +
  /// out->cols) of the mask into `out` (CV_8UC1, preallocated): 255 inside, 0 outside; pixels of
  /// `out` beyond the image are left as they are.
  void decodeInto(int col_begin, int row_begin, cv::Mat* out) const;
  /// Number of inside pixels.
  size_t insideCount() const;
  /// Bounding box of the inside pixels (empty when there are none), as cv::boundingRect.
  cv::Rect insideBounds() const;
  /// Bytes held by the runs.
  size_t memoryBytes() const { return (runs_.size() + row_first_.size()) * sizeof(int32_t); }

 private:
  cv::Size size_;
  /// Runs of row r: elements [row_first_[r], row_first_[r + 1]) of runs_, pairs of (first
  /// column, one past the last column).
  std::vector<int32_t> row_first_;
  std::vector<int32_t> runs_;
};

/// silhouetteBounds() of the decoded mask, without decoding it.
SilhouetteBounds silhouetteBounds(const RunLengthMask& mask, bool border_bounds_object);

}  // namespace sift_hull
