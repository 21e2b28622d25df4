#include "sift_hull/hull/run_length_mask.h"

#include <algorithm>
#include <cstring>
#include <stdexcept>

namespace sift_hull {

RunLengthMask::RunLengthMask(const cv::Mat& mask) : size_(mask.size()) {
  if (mask.empty() || mask.type() != CV_8UC1) {
    throw std::invalid_argument("silhouette must be a non-empty CV_8UC1 mask");
  }
  row_first_.reserve(mask.rows + 1);
  for (int row = 0; row < mask.rows; ++row) {
    row_first_.push_back(static_cast<int32_t>(runs_.size()));
    const uint8_t* pixel = mask.ptr<uint8_t>(row);
    int col = 0;
    while (col < mask.cols) {
      while (col < mask.cols && pixel[col] == 0) ++col;
      if (col == mask.cols) break;
      const int begin = col;
      while (col < mask.cols && pixel[col] != 0) ++col;
      runs_.push_back(begin);
      runs_.push_back(col);
    }
  }
  row_first_.push_back(static_cast<int32_t>(runs_.size()));
  runs_.shrink_to_fit();
}

bool RunLengthMask::at(int u_px, int v_px) const {
  if (u_px < 0 || v_px < 0 || u_px >= size_.width || v_px >= size_.height) return false;
  const int32_t* first = runs_.data() + row_first_[v_px];
  const int32_t* last = runs_.data() + row_first_[v_px + 1];
  // The first run end beyond u: inside when its begin is at or before u.
  for (const int32_t* run = first; run != last; run += 2) {
    if (run[1] > u_px) return run[0] <= u_px;
  }
  return false;
}

cv::Mat RunLengthMask::decode() const {
  cv::Mat mask = cv::Mat::zeros(size_, CV_8UC1);
  decodeInto(0, 0, &mask);
  return mask;
}

void RunLengthMask::decodeInto(int col_begin, int row_begin, cv::Mat* out) const {
  const int first_row = std::max(row_begin, 0);
  const int last_row = std::min(row_begin + out->rows, size_.height);
  const int first_col = std::max(col_begin, 0);
  const int last_col = std::min(col_begin + out->cols, size_.width);
  if (first_col >= last_col) return;
  for (int row = first_row; row < last_row; ++row) {
    uint8_t* target = out->ptr<uint8_t>(row - row_begin) - col_begin;
    std::memset(target + first_col, 0, last_col - first_col);
    for (int32_t i = row_first_[row]; i < row_first_[row + 1]; i += 2) {
      const int begin = std::max<int>(runs_[i], first_col);
      const int end = std::min<int>(runs_[i + 1], last_col);
      if (begin < end) std::memset(target + begin, 255, end - begin);
    }
  }
}

size_t RunLengthMask::insideCount() const {
  size_t count = 0;
  for (size_t i = 0; i + 1 < runs_.size(); i += 2) count += runs_[i + 1] - runs_[i];
  return count;
}

cv::Rect RunLengthMask::insideBounds() const {
  int first_row = -1, last_row = -1, first_col = size_.width, end_col = 0;
  for (int row = 0; row < size_.height; ++row) {
    if (row_first_[row] == row_first_[row + 1]) continue;
    if (first_row < 0) first_row = row;
    last_row = row;
    first_col = std::min<int>(first_col, runs_[row_first_[row]]);
    end_col = std::max<int>(end_col, runs_[row_first_[row + 1] - 1]);
  }
  if (first_row < 0) return cv::Rect();
  return cv::Rect(first_col, first_row, end_col - first_col, last_row - first_row + 1);
}

SilhouetteBounds silhouetteBounds(const RunLengthMask& mask, bool border_bounds_object) {
  if (mask.empty()) throw std::invalid_argument("silhouetteBounds: the mask is empty");
  return boundsOfInside(mask.insideBounds(), mask.size(), border_bounds_object);
}

}  // namespace sift_hull
