#include "sift_hull/synthetic/mask_render.h"

#include <algorithm>
#include <opencv2/core/utility.hpp>
#include <stdexcept>

namespace sift_hull {
namespace {

bool hits(const Shape& shape, const PinholeCamera& camera, int u, int v) {
  RayHit hit;
  return shape.firstHit(camera.centre(), camera.rayDirection(Eigen::Vector2d(u, v)), &hit);
}

/// Whether the samples around block (column, row) and its neighbours all agree.
bool uniform(const cv::Mat& samples, int column, int row) {
  const uint8_t first = samples.at<uint8_t>(row, column);
  for (int r = std::max(row - 1, 0); r <= std::min(row + 2, samples.rows - 1); ++r) {
    for (int c = std::max(column - 1, 0); c <= std::min(column + 2, samples.cols - 1); ++c) {
      if (samples.at<uint8_t>(r, c) != first) return false;
    }
  }
  return true;
}

}  // namespace

cv::Mat renderMask(const Shape& shape, const PinholeCamera& camera, cv::Size size, int step) {
  if (size.empty() || step < 1) throw std::invalid_argument("renderMask: empty size or step < 1");
  // Sample (c, r) is pixel (min(c * step, width - 1), min(r * step, height - 1)).
  const int sample_cols = (size.width - 1 + step - 1) / step + 1;
  const int sample_rows = (size.height - 1 + step - 1) / step + 1;
  cv::Mat samples(sample_rows, sample_cols, CV_8UC1);
  cv::parallel_for_(cv::Range(0, sample_rows), [&](const cv::Range& rows) {
    for (int r = rows.start; r < rows.end; ++r) {
      for (int c = 0; c < sample_cols; ++c) {
        samples.at<uint8_t>(r, c) = hits(shape, camera, std::min(c * step, size.width - 1),
                                         std::min(r * step, size.height - 1))
                                        ? 255
                                        : 0;
      }
    }
  });
  cv::Mat mask(size, CV_8UC1);
  const int block_rows = std::max(sample_rows - 1, 1), block_cols = std::max(sample_cols - 1, 1);
  cv::parallel_for_(cv::Range(0, block_rows), [&](const cv::Range& rows) {
    for (int row = rows.start; row < rows.end; ++row) {
      const int v_end = row == block_rows - 1 ? size.height : (row + 1) * step;
      for (int column = 0; column < block_cols; ++column) {
        const int u_end = column == block_cols - 1 ? size.width : (column + 1) * step;
        const bool same = uniform(samples, column, row);
        for (int v = row * step; v < v_end; ++v) {
          uint8_t* pixel = mask.ptr<uint8_t>(v);
          for (int u = column * step; u < u_end; ++u) {
            pixel[u] = same ? samples.at<uint8_t>(row, column)
                            : (hits(shape, camera, u, v) ? 255 : 0);
          }
        }
      }
    }
  });
  return mask;
}

}  // namespace sift_hull
