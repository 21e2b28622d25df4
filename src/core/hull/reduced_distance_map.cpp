#include "sift_hull/hull/reduced_distance_map.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <opencv2/imgproc.hpp>
#include <stdexcept>

#include "sift_hull/hull/octree.h"

namespace sift_hull {
namespace {

/// Blocks per side of the tiles whose full-resolution transforms give the exact band.
constexpr int kTileBlocks = 32;
/// Half a block's diagonal over its edge, rounded up.
constexpr float kHalfDiagonal = 0.7072f;

/// The rectangle of the padded image (padding pixels around the image) that counts as inside
/// because of the bounds, as SignedDistanceMap's padded mask has it: the bounds' rectangle, its
/// open sides reaching the padded image's edge.
cv::Rect boundsRect(const SilhouetteBounds& bounds, cv::Size padded, int padding) {
  const int first_col =
      bounds.has_u_min ? static_cast<int>(std::ceil(bounds.u_min_px)) + padding : 0;
  const int last_col = bounds.has_u_max ? static_cast<int>(std::floor(bounds.u_max_px)) + padding
                                        : padded.width - 1;
  const int first_row =
      bounds.has_v_min ? static_cast<int>(std::ceil(bounds.v_min_px)) + padding : 0;
  const int last_row = bounds.has_v_max ? static_cast<int>(std::floor(bounds.v_max_px)) + padding
                                        : padded.height - 1;
  return cv::Rect(first_col, first_row, last_col - first_col + 1, last_row - first_row + 1) &
         cv::Rect(cv::Point(0, 0), padded);
}

/// The padded mask over `region` (padded image coordinates, may reach beyond the padded image's
/// right and bottom edges, where the last column / row is repeated): 255 inside, 0 outside.
cv::Mat paddedRegion(const RunLengthMask& mask, const SilhouetteBounds& bounds, int padding,
                     const cv::Rect& region) {
  const cv::Size padded(mask.size().width + 2 * padding, mask.size().height + 2 * padding);
  const cv::Rect valid = region & cv::Rect(cv::Point(0, 0), padded);
  cv::Mat inside = cv::Mat::zeros(valid.size(), CV_8UC1);
  const cv::Rect kept = boundsRect(bounds, padded, padding) & valid;
  if (!kept.empty()) inside(kept - valid.tl()).setTo(255);
  mask.decodeInto(valid.x - padding, valid.y - padding, &inside);
  if (valid.size() == region.size()) return inside;
  cv::Mat extended;
  cv::copyMakeBorder(inside, extended, 0, region.height - valid.height, 0,
                     region.width - valid.width, cv::BORDER_REPLICATE);
  return extended;
}

/// Inside pixels per block of `reduction` x `reduction` pixels (CV_8UC1; reduction <= 15).
cv::Mat blockCounts(const cv::Mat& inside, int reduction) {
  const int block_cols = inside.cols / reduction;
  cv::Mat counts(inside.rows / reduction, block_cols, CV_8UC1);
  std::vector<int> row_counts(inside.cols);
  std::vector<int> sums(block_cols);
  for (int block_row = 0; block_row < counts.rows; ++block_row) {
    std::fill(sums.begin(), sums.end(), 0);
    for (int row = block_row * reduction; row < (block_row + 1) * reduction; ++row) {
      const uint8_t* pixel = inside.ptr<uint8_t>(row);
      for (int col = 0; col < inside.cols; ++col) row_counts[col] = pixel[col] & 1;
      for (int col = 0; col < inside.cols; ++col) sums[col / reduction] += row_counts[col];
    }
    uint8_t* count = counts.ptr<uint8_t>(block_row);
    for (int block = 0; block < block_cols; ++block) count[block] = static_cast<uint8_t>(sums[block]);
  }
  return counts;
}

/// Blocks whose 3x3 neighbourhood holds an inside and an outside pixel (255), else 0: every
/// boundary between an inside and an outside pixel lies in one of them.
cv::Mat contourBlocks(const cv::Mat& counts, int full) {
  cv::Mat most, least;
  const cv::Mat kernel = cv::getStructuringElement(cv::MORPH_RECT, cv::Size(3, 3));
  cv::dilate(counts, most, kernel);
  cv::erode(counts, least, kernel);
  return (most > 0) & (least < full);
}

/// Signed lower bounds of the full-resolution map's magnitude at the samples, from the distance
/// in blocks to the nearest contour block; 0 on contour blocks.
cv::Mat coarseDistances(const cv::Mat& counts, const cv::Mat& contour, int reduction,
                        cv::Mat* blocks_to_contour) {
  cv::distanceTransform(contour == 0, *blocks_to_contour, cv::DIST_L2, cv::DIST_MASK_PRECISE,
                        CV_32F);
  const int full = reduction * reduction;
  cv::Mat distance(counts.size(), CV_32FC1);
  for (int row = 0; row < counts.rows; ++row) {
    const uint8_t* count = counts.ptr<uint8_t>(row);
    const float* blocks = blocks_to_contour->ptr<float>(row);
    float* value = distance.ptr<float>(row);
    for (int col = 0; col < counts.cols; ++col) {
      const float magnitude =
          std::max(0.0f, reduction * (blocks[col] - kHalfDiagonal) - 0.5f);
      value[col] = count[col] == full ? -magnitude : (count[col] == 0 ? magnitude : 0.0f);
    }
  }
  return distance;
}

/// Full-resolution transforms of one crop of the padded mask: the map's values at its pixels,
/// and which pixels' values cannot depend on what lies beyond the crop.
struct CropDistances {
  cv::Rect crop;         ///< in the region's pixels
  cv::Mat value_px;      ///< CV_32FC1, SignedDistanceMap's values
  cv::Mat distance_px;   ///< CV_32FC1, distance to the nearest opposite pixel
  bool open[4] = {};     ///< sides (left, top, right, bottom) cut inside the region
  /// The value at crop pixel (col, row), or NaN when a nearer opposite pixel may lie beyond an
  /// open side.
  float valueAt(int col, int row) const {
    const float distance = distance_px.at<float>(row, col);
    const float far = std::numeric_limits<float>::infinity();
    const float reach = std::min({open[0] ? col + 1.0f : far, open[1] ? row + 1.0f : far,
                                  open[2] ? float(crop.width - col) : far,
                                  open[3] ? float(crop.height - row) : far});
    return distance <= reach ? value_px.at<float>(row, col)
                             : std::numeric_limits<float>::quiet_NaN();
  }
};

CropDistances cropDistances(const cv::Mat& inside, const cv::Rect& crop) {
  CropDistances result;
  result.crop = crop;
  result.open[0] = crop.x > 0, result.open[1] = crop.y > 0;
  result.open[2] = crop.br().x < inside.cols, result.open[3] = crop.br().y < inside.rows;
  const cv::Mat region = inside(crop);
  cv::Mat to_outside, to_inside;
  cv::distanceTransform(region, to_outside, cv::DIST_L2, cv::DIST_MASK_PRECISE, CV_32F);
  cv::distanceTransform(region == 0, to_inside, cv::DIST_L2, cv::DIST_MASK_PRECISE, CV_32F);
  result.distance_px = to_outside + to_inside;  // one of the two is 0 at each pixel
  result.value_px.create(region.size(), CV_32FC1);
  for (int row = 0; row < region.rows; ++row) {
    const uint8_t* is_inside = region.ptr<uint8_t>(row);
    const float* distance = result.distance_px.ptr<float>(row);
    float* value = result.value_px.ptr<float>(row);
    for (int col = 0; col < region.cols; ++col) {
      value[col] = is_inside[col] ? 0.5f - distance[col] : distance[col] - 0.5f;
    }
  }
  return result;
}

/// The full-resolution map's bilinear look-up at the sample of block (col, row): the mean of
/// the one (odd reduction) or four (even) pixels around it; NaN when one of them is not exact.
float exactSample(const CropDistances& crop, int block_col, int block_row, int reduction) {
  const int first_col = block_col * reduction + (reduction - 1) / 2 - crop.crop.x;
  const int first_row = block_row * reduction + (reduction - 1) / 2 - crop.crop.y;
  const int last = reduction % 2 == 0 ? 1 : 0;
  float sum = 0.0f;
  for (int dr = 0; dr <= last; ++dr) {
    for (int dc = 0; dc <= last; ++dc) sum += crop.valueAt(first_col + dc, first_row + dr);
  }
  return last == 1 ? 0.25f * sum : sum;
}

/// Replaces the samples within kExactBandBlocks blocks of the contour by exact ones, tile by
/// tile.
void refineBand(const cv::Mat& inside, const cv::Mat& blocks_to_contour, int reduction,
                cv::Mat* distance) {
  const cv::Mat band = blocks_to_contour <= kExactBandBlocks;
  const int margin = (kExactBandBlocks + 2) * reduction + 2;
  const cv::Rect all(0, 0, inside.cols, inside.rows);
  for (int tile_row = 0; tile_row < band.rows; tile_row += kTileBlocks) {
    for (int tile_col = 0; tile_col < band.cols; tile_col += kTileBlocks) {
      const cv::Rect tile = cv::Rect(tile_col, tile_row, kTileBlocks, kTileBlocks) &
                            cv::Rect(0, 0, band.cols, band.rows);
      if (cv::countNonZero(band(tile)) == 0) continue;
      const cv::Rect pixels(tile.x * reduction - margin, tile.y * reduction - margin,
                            tile.width * reduction + 2 * margin,
                            tile.height * reduction + 2 * margin);
      const CropDistances crop = cropDistances(inside, pixels & all);
      for (int row = tile.y; row < tile.br().y; ++row) {
        for (int col = tile.x; col < tile.br().x; ++col) {
          if (!band.at<uint8_t>(row, col)) continue;
          const float exact = exactSample(crop, col, row, reduction);
          if (!std::isnan(exact)) distance->at<float>(row, col) = exact;
        }
      }
    }
  }
}

}  // namespace

int distanceReduction(const PinholeCamera& camera, const Box3d& box, const HullConfig& config) {
  if (config.distance_reduction > 0) return config.distance_reduction;
  const double voxel_m = HullCube::around(box, config.max_depth).resolution_m;
  double farthest_m = 0.0;
  for (int corner = 0; corner < 8; ++corner) {
    const Eigen::Vector3d X_W((corner & 1) ? box.max_W.x() : box.min_W.x(),
                              (corner & 2) ? box.max_W.y() : box.min_W.y(),
                              (corner & 4) ? box.max_W.z() : box.min_W.z());
    const double depth_m = camera.depth(X_W);
    if (!(depth_m > 0.0)) return 1;
    farthest_m = std::max(farthest_m, depth_m);
  }
  const double focal_px = std::min(camera.K()(0, 0), camera.K()(1, 1));
  const double voxel_px = focal_px * voxel_m / farthest_m;
  int reduction = 1;
  while (2 * reduction <= voxel_px && 2 * reduction <= kMaxAutomaticDistanceReduction) {
    reduction *= 2;
  }
  return reduction;
}

float reducedDistanceErrorBound_px(int reduction) {
  return reduction > 1 ? static_cast<float>(reduction) : 0.0f;
}

SignedDistanceMap reducedSignedDistanceMap(const RunLengthMask& mask,
                                           const SilhouetteBounds& bounds, int padding_px,
                                           int reduction) {
  if (mask.empty()) throw std::invalid_argument("silhouette must be a non-empty CV_8UC1 mask");
  if (reduction < 1 || reduction > kMaxDistanceReduction) {
    throw std::invalid_argument("reducedSignedDistanceMap: reduction outside [1, 15]");
  }
  if (reduction == 1 || bounds.empty) return SignedDistanceMap(mask.decode(), bounds, padding_px);
  const cv::Size padded(mask.size().width + 2 * padding_px, mask.size().height + 2 * padding_px);
  const cv::Rect kept = boundsRect(bounds, padded, padding_px);
  const cv::Rect window = cv::Rect(kept.x - padding_px, kept.y - padding_px,
                                   kept.width + 2 * padding_px, kept.height + 2 * padding_px) &
                          cv::Rect(cv::Point(0, 0), padded);
  const int block_cols = std::max(2, (window.width + reduction - 1) / reduction);
  const int block_rows = std::max(2, (window.height + reduction - 1) / reduction);
  const cv::Rect region(window.x, window.y, block_cols * reduction, block_rows * reduction);
  const cv::Mat inside = paddedRegion(mask, bounds, padding_px, region);
  const cv::Mat counts = blockCounts(inside, reduction);
  cv::Mat blocks_to_contour;
  cv::Mat distance = coarseDistances(counts, contourBlocks(counts, reduction * reduction),
                                     reduction, &blocks_to_contour);
  refineBand(inside, blocks_to_contour, reduction, &distance);
  return SignedDistanceMap(distance, mask.size(), region.tl() - cv::Point(padding_px, padding_px),
                           reduction, reducedDistanceErrorBound_px(reduction));
}

}  // namespace sift_hull
