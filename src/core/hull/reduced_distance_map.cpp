#include "sift_hull/hull/reduced_distance_map.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <opencv2/imgproc.hpp>
#include <stdexcept>
#include <vector>

#include "hull/distance_kernel.h"
#include "sift_hull/hull/octree.h"

namespace sift_hull {
namespace {

/// Blocks per side of the tiles whose full-resolution transforms give the exact band.
constexpr int kTileBlocks = 64;
/// Half a block's diagonal over its edge, rounded up.
constexpr float kHalfDiagonal = 0.7072f;

/// The rectangle of the padded image (padding pixels around the image) that counts as inside
/// because of the bounds, as SignedDistanceMap's padded mask has it: the bounds' rectangle, its
/// open sides reaching the padded image's edge.
cv::Rect boundsRect(const SilhouetteBounds& bounds, cv::Size padded, int padding) {
  const int first_col =
      bounds.has_u_min ? static_cast<int>(std::ceil(bounds.u_min_px)) + padding : 0;
  const int last_col =
      bounds.has_u_max ? static_cast<int>(std::floor(bounds.u_max_px)) + padding : padded.width - 1;
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
  std::vector<int> sums(block_cols);
  for (int block_row = 0; block_row < counts.rows; ++block_row) {
    std::fill(sums.begin(), sums.end(), 0);
    for (int row = block_row * reduction; row < (block_row + 1) * reduction; ++row) {
      const uint8_t* pixel = inside.ptr<uint8_t>(row);
      for (int block = 0; block < block_cols; ++block, pixel += reduction) {
        int sum = 0;  // of 0 / 255 values
        for (int k = 0; k < reduction; ++k) sum += pixel[k];
        sums[block] += sum;
      }
    }
    uint8_t* count = counts.ptr<uint8_t>(block_row);
    for (int block = 0; block < block_cols; ++block) {
      count[block] = static_cast<uint8_t>(sums[block] / 255);
    }
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
      // Lowered by `reduction` more, the interpolation's bound (refineBand).
      const float magnitude =
          std::max(0.0f, reduction * (blocks[col] - kHalfDiagonal - 1.0f) - 0.5f);
      value[col] = count[col] == full ? -magnitude : (count[col] == 0 ? magnitude : 0.0f);
    }
  }
  return distance;
}

/// SignedDistanceMap's values over one crop of the padded mask (CV_32FC1), NaN where a nearer
/// opposite pixel may lie beyond a side of the crop that is not the region's edge.
cv::Mat cropValues(const cv::Mat& inside, const cv::Rect& crop) {
  const bool open_left = crop.x > 0, open_top = crop.y > 0;
  const bool open_right = crop.br().x < inside.cols, open_bottom = crop.br().y < inside.rows;
  const cv::Mat region = inside(crop);
  cv::Mat to_outside, to_inside;
  cv::distanceTransform(region, to_outside, cv::DIST_L2, cv::DIST_MASK_PRECISE, CV_32F);
  cv::distanceTransform(region == 0, to_inside, cv::DIST_L2, cv::DIST_MASK_PRECISE, CV_32F);
  const float far = std::numeric_limits<float>::infinity();
  cv::Mat values(region.size(), CV_32FC1);
  for (int row = 0; row < region.rows; ++row) {
    const uint8_t* is_inside = region.ptr<uint8_t>(row);
    const float* outward = to_outside.ptr<float>(row);
    const float* inward = to_inside.ptr<float>(row);
    float* value = values.ptr<float>(row);
    const float vertical = std::min(open_top ? row + 1.0f : far,
                                    open_bottom ? static_cast<float>(region.rows - row) : far);
    for (int col = 0; col < region.cols; ++col) {
      const float reach = std::min({vertical, open_left ? col + 1.0f : far,
                                    open_right ? static_cast<float>(region.cols - col) : far});
      const float distance = is_inside[col] ? outward[col] : inward[col];
      value[col] = distance > reach ? std::numeric_limits<float>::quiet_NaN()
                                    : (is_inside[col] ? 0.5f - distance : distance - 0.5f);
    }
  }
  return values;
}

/// The full-resolution map's bilinear look-up at crop coordinates (u, v), clamped to the crop
/// (reached only where the crop ends with the region, as the full map clamps to its window);
/// NaN when a pixel it needs is unknown.
float cropLookUp(const cv::Mat& values, float u, float v) {
  u = detail::clampToMap(u, detail::lookUpLimit(values.cols));
  v = detail::clampToMap(v, detail::lookUpLimit(values.rows));
  const int u0 = static_cast<int>(u), v0 = static_cast<int>(v);
  const float fu = u - u0, fv = v - v0;
  const float* top = values.ptr<float>(v0) + u0;
  const float* bottom = values.ptr<float>(v0 + 1) + u0;
  const float upper = top[0] + fu * (top[1] - top[0]);
  const float lower = bottom[0] + fu * (bottom[1] - bottom[0]);
  return upper + fv * (lower - upper);
}

/// One tile of blocks and the full-resolution values around it.
struct Tile {
  cv::Rect blocks;  ///< in the block grid
  cv::Rect crop;    ///< in the region's pixels
  cv::Mat values;   ///< cropValues
};

/// The tiles holding a block of `needed`, with their crops' full-resolution values.
std::vector<Tile> bandTiles(const cv::Mat& inside, const cv::Mat& needed, int reduction) {
  // A checked block lies within kExactBandBlocks + 1 blocks of a contour block, which has both
  // kinds of pixels in its 3x3 neighbourhood: the nearest opposite pixel is nearer than this.
  const int margin = (kExactBandBlocks + 5) * reduction + 2;
  const cv::Rect all(0, 0, inside.cols, inside.rows);
  std::vector<Tile> tiles;
  for (int tile_row = 0; tile_row < needed.rows; tile_row += kTileBlocks) {
    for (int tile_col = 0; tile_col < needed.cols; tile_col += kTileBlocks) {
      Tile tile;
      tile.blocks = cv::Rect(tile_col, tile_row, kTileBlocks, kTileBlocks) &
                    cv::Rect(0, 0, needed.cols, needed.rows);
      if (cv::countNonZero(needed(tile.blocks)) == 0) continue;
      tile.crop = cv::Rect(tile.blocks.x * reduction - margin, tile.blocks.y * reduction - margin,
                           tile.blocks.width * reduction + 2 * margin,
                           tile.blocks.height * reduction + 2 * margin) &
                  all;
      tile.values = cropValues(inside, tile.crop);
      tiles.push_back(std::move(tile));
    }
  }
  return tiles;
}

/// Sets the samples of the band's blocks of a tile to the full-resolution map's look-up there
/// (the mean of the one or four pixels around the sample), where it is known.
void setExactSamples(const Tile& tile, const cv::Mat& band, int reduction, cv::Mat* distance) {
  const float first = 0.5f * (reduction - 1);
  for (int row = tile.blocks.y; row < tile.blocks.br().y; ++row) {
    for (int col = tile.blocks.x; col < tile.blocks.br().x; ++col) {
      if (!band.at<uint8_t>(row, col)) continue;
      const float exact = cropLookUp(tile.values, col * reduction + first - tile.crop.x,
                                     row * reduction + first - tile.crop.y);
      if (!std::isnan(exact)) distance->at<float>(row, col) = exact;
    }
  }
}

/// The largest excess of the reduced map over the full-resolution one, sign(r) (r - f), over the
/// pixels of a tile's `checked` blocks: at pixel centres, and for an even reduction also halfway
/// between them, where the pieces of both bilinear interpolants meet, so that this is the
/// largest excess anywhere in those blocks. +inf when a full-resolution value is unknown.
float largestExcess(const Tile& tile, const cv::Mat& checked, const cv::Mat& distance,
                    int reduction) {
  const float first = 0.5f * (reduction - 1), inverse = 1.0f / reduction;
  const float step = reduction % 2 == 0 ? 0.5f : 1.0f;
  const float u_high = detail::lookUpLimit(distance.cols);
  const float v_high = detail::lookUpLimit(distance.rows);
  float largest = 0.0f;
  for (int row = tile.blocks.y; row < tile.blocks.br().y; ++row) {
    for (int col = tile.blocks.x; col < tile.blocks.br().x; ++col) {
      if (!checked.at<uint8_t>(row, col)) continue;
      for (float v = row * reduction; v < (row + 1) * reduction; v += step) {
        for (float u = col * reduction; u < (col + 1) * reduction; u += step) {
          const float full = cropLookUp(tile.values, u - tile.crop.x, v - tile.crop.y);
          if (std::isnan(full)) return std::numeric_limits<float>::infinity();
          const float reduced = detail::lookUp(distance.ptr<float>(), distance.cols, u_high, v_high,
                                               (u - first) * inverse, (v - first) * inverse);
          const float sign = reduced > 0.0f ? 1.0f : (reduced < 0.0f ? -1.0f : 0.0f);
          largest = std::max(largest, sign * (reduced - full));
        }
      }
    }
  }
  return largest;
}

/// Replaces the samples within kExactBandBlocks blocks of the contour by exact ones, tile by
/// tile, and returns the map's error bound: the largest excess over the full-resolution map
/// around the band (largestExcess), at most `reduction`. Elsewhere the samples are lowered by
/// `reduction` below the full-resolution magnitude (coarseDistances), which covers the
/// interpolation between them.
float refineBand(const cv::Mat& inside, const cv::Mat& blocks_to_contour, int reduction,
                 cv::Mat* distance) {
  const cv::Mat band = blocks_to_contour <= kExactBandBlocks;
  cv::Mat checked;  // every block a cell with an exact sample reaches
  cv::dilate(band, checked, cv::getStructuringElement(cv::MORPH_RECT, cv::Size(3, 3)));
  const std::vector<Tile> tiles = bandTiles(inside, checked, reduction);
  for (const Tile& tile : tiles) setExactSamples(tile, band, reduction, distance);
  float largest = 0.0f;
  for (const Tile& tile : tiles) {
    largest = std::max(largest, largestExcess(tile, checked, *distance, reduction));
  }
  // Rounding of the kernel's folded projection: a thousandth of a pixel.
  return std::min(largest + 1e-3f, reducedDistanceErrorBound_px(reduction));
}

}  // namespace

int distanceReduction(const PinholeCamera& camera, cv::Size image_size, const Box3d& box,
                      const HullConfig& config) {
  if (config.distance_reduction > 0) return config.distance_reduction;
  if (image_size.area() < kMinReducedImagePixels) return 1;
  const double voxel_m = HullCube::forConfig(box, config).resolution_m;
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
  return static_cast<int>(
      std::clamp(std::floor(voxel_px), 1.0, static_cast<double>(kMaxAutomaticDistanceReduction)));
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
  const float error_px = refineBand(inside, blocks_to_contour, reduction, &distance);
  return SignedDistanceMap(distance, mask.size(), region.tl() - cv::Point(padding_px, padding_px),
                           reduction, error_px);
}

}  // namespace sift_hull
