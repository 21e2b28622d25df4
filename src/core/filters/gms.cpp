// Grid-based Motion Statistics: J. Bian, W.-Y. Lin, Y. Matsushita, S.-K. Yeung, T. D. Nguyen,
// M.-M. Cheng, "GMS: Grid-based Motion Statistics for Fast, Ultra-robust Feature
// Correspondence", CVPR 2017.
//
// Sec. 3 (motion statistics): a true match has many other matches in its neighbourhood that move
// to the neighbourhood of its partner; a false one has few. Sec. 4 (grid framework, Algorithm 1):
// each left cell i is paired with the right cell j receiving most of its matches; the pair's
// score is S_ij = sum_{k=1..9} |X_{i^k j^k}| over the 3x3 neighbourhoods, and the pair is kept
// when S_ij > tau_i = alpha * sqrt(n_i), with n_i the mean number of matches per cell in the left
// neighbourhood (alpha = 6, a 20x20 grid). The grid is run four times, shifted by half a cell in
// x, y and both, and a match is kept if any run keeps it. Rotation and scale changes are handled
// by trying 8 rotated neighbourhood patterns and 5 relative scales of the right grid, keeping
// the combination with the most inliers.
//
// Like the authors' code, only the left grid is shifted, n_i averages over the neighbour pairs
// that exist in both grids, and ties favour the unrotated pattern and the unscaled right grid.
// Points outside their image ([0, width) x [0, height)) are dropped: they count in no cell, are
// never kept and score 0.

#include "sift_hull/filters/gms.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <limits>
#include <stdexcept>
#include <string>
#include <unordered_map>
#include <vector>

#include "sift_hull/limits.h"

namespace sift_hull {
namespace {

constexpr int kNeighbourhoodSize = 9;  // 3x3 cells, row-major, centre at kCentrePosition
constexpr int kCentrePosition = 4;
constexpr int kRotationCount = 8;  // the outer ring of the 3x3 neighbourhood turned 45 deg a step
constexpr int kShiftCount = 4;     // unshifted, half a cell in x, in y, in both
constexpr int kNoCell = -1;

// Right grid size relative to the left one; 1 first so that ties keep the unscaled grid.
constexpr std::array<double, 5> kRightGridScales = {1.0, 0.5, 0.70710678118654752,
                                                    1.4142135623730951, 2.0};

// The 8 outer positions of the 3x3 neighbourhood in clockwise order.
constexpr std::array<int, 8> kClockwiseRing = {0, 1, 2, 5, 8, 7, 6, 3};

/// A cols x rows grid over normalised image coordinates [0, 1) x [0, 1).
struct Grid {
  int cols = 0;
  int rows = 0;

  int cellCount() const { return cols * rows; }

  /// The cell at `position` (0..8, row-major) of the 3x3 neighbourhood of `cell`, or kNoCell.
  int neighbour(int cell, int position) const {
    const int x = cell % cols + position % 3 - 1;
    const int y = cell / cols + position / 3 - 1;
    if (x < 0 || x >= cols || y < 0 || y >= rows) return kNoCell;
    return x + y * cols;
  }
};

/// Neighbourhood position of the right cell that pairs with left `position` when the image
/// content turned by `rotation` steps of 45 degrees (0: no rotation).
int rotatedPosition(int position, int rotation) {
  if (position == kCentrePosition) return kCentrePosition;
  const int ring_index = static_cast<int>(
      std::find(kClockwiseRing.begin(), kClockwiseRing.end(), position) - kClockwiseRing.begin());
  return kClockwiseRing[(ring_index - rotation + kRotationCount) % kRotationCount];
}

/// A match's points in normalised image coordinates; `usable` is false when either is non-finite
/// or outside its image.
struct NormalisedMatch {
  cv::Point2d left;
  cv::Point2d right;
  bool usable = false;
};

bool isInside(const cv::Point2d& normalised) {
  return normalised.x >= 0.0 && normalised.x < 1.0 && normalised.y >= 0.0 && normalised.y < 1.0;
}

cv::Point2d normalise(const cv::Point2f& point, const cv::Size& image_size) {
  return {point.x / static_cast<double>(image_size.width),
          point.y / static_cast<double>(image_size.height)};
}

void checkKeypointIndices(const PutativeMatches& input) {
  for (const cv::DMatch& match : input.matches) {
    if (match.queryIdx < 0 || static_cast<size_t>(match.queryIdx) >= input.left_keypoints.size() ||
        match.trainIdx < 0 || static_cast<size_t>(match.trainIdx) >= input.right_keypoints.size()) {
      throw std::invalid_argument("filterGms: a match indexes a keypoint that does not exist");
    }
  }
}

std::vector<NormalisedMatch> normaliseMatches(const PutativeMatches& input) {
  std::vector<NormalisedMatch> normalised(input.matches.size());
  for (size_t i = 0; i < input.matches.size(); ++i) {
    if (!input.hasFinitePositions(i)) continue;
    const cv::Point2f& left = input.left(i).pt;
    const cv::Point2f& right = input.right(i).pt;
    normalised[i].left = normalise(left, input.left_image_size);
    normalised[i].right = normalise(right, input.right_image_size);
    normalised[i].usable = isInside(normalised[i].left) && isInside(normalised[i].right);
  }
  return normalised;
}

/// Cell of an unshifted grid; `coordinate` * size can round up to size just below 1.
int cellAlong(double coordinate, int size) {
  return std::min(static_cast<int>(std::floor(coordinate * size)), size - 1);
}

/// Cell of the left grid shifted by half a cell along x (shift bit 0) and/or y (shift bit 1).
/// The half-cell strip at the far border lies outside the shifted grid; the unshifted run
/// covers it.
int shiftedLeftCell(const cv::Point2d& point, const Grid& grid, int shift) {
  const double offset_x = (shift & 1) ? 0.5 : 0.0;
  const double offset_y = (shift & 2) ? 0.5 : 0.0;
  const int x = static_cast<int>(std::floor(point.x * grid.cols + offset_x));
  const int y = static_cast<int>(std::floor(point.y * grid.rows + offset_y));
  if (x >= grid.cols || y >= grid.rows) return kNoCell;
  return x + y * grid.cols;
}

/// How the usable matches fall into (left cell, right cell) pairs for one grid placement.
struct MotionStatistics {
  Grid left_grid;
  Grid right_grid;
  std::vector<int> left_cell;                  // per match; kNoCell when not counted
  std::vector<int> right_cell;                 // per match; kNoCell when not counted
  std::vector<int> matches_in_left_cell;       // per left cell
  std::unordered_map<int64_t, int> pair_size;  // |X_ij|, keyed by pairKey(i, j)
  std::vector<int> best_right_cell;            // per left cell; kNoCell when it has no match

  int64_t pairKey(int left, int right) const {
    return static_cast<int64_t>(left) * right_grid.cellCount() + right;
  }
  int pairSizeOf(int left, int right) const {
    const auto found = pair_size.find(pairKey(left, right));
    return found == pair_size.end() ? 0 : found->second;
  }
};

/// Per left cell, the right cell receiving most of its matches (the lowest index on ties).
void findBestRightCells(MotionStatistics* stats) {
  const int right_cells = stats->right_grid.cellCount();
  std::vector<int> best_size(stats->left_grid.cellCount(), 0);
  stats->best_right_cell.assign(stats->left_grid.cellCount(), kNoCell);
  for (const auto& [key, size] : stats->pair_size) {
    const int left = static_cast<int>(key / right_cells);
    const int right = static_cast<int>(key % right_cells);
    int& best = stats->best_right_cell[left];
    if (size > best_size[left] || (size == best_size[left] && right < best)) {
      best_size[left] = size;
      best = right;
    }
  }
}

MotionStatistics countMotion(const std::vector<NormalisedMatch>& matches, const Grid& left_grid,
                             const Grid& right_grid, int shift) {
  MotionStatistics stats;
  stats.left_grid = left_grid;
  stats.right_grid = right_grid;
  stats.left_cell.assign(matches.size(), kNoCell);
  stats.right_cell.assign(matches.size(), kNoCell);
  stats.matches_in_left_cell.assign(left_grid.cellCount(), 0);
  for (size_t i = 0; i < matches.size(); ++i) {
    if (!matches[i].usable) continue;
    const int left = shiftedLeftCell(matches[i].left, left_grid, shift);
    if (left == kNoCell) continue;
    const int right = cellAlong(matches[i].right.x, right_grid.cols) +
                      cellAlong(matches[i].right.y, right_grid.rows) * right_grid.cols;
    stats.left_cell[i] = left;
    stats.right_cell[i] = right;
    ++stats.matches_in_left_cell[left];
    ++stats.pair_size[stats.pairKey(left, right)];
  }
  findBestRightCells(&stats);
  return stats;
}

/// S / tau of the pair (left cell, its best right cell) under the given neighbourhood rotation.
double pairScore(const MotionStatistics& stats, int left, int rotation, double threshold_factor) {
  const int right = stats.best_right_cell[left];
  int support = 0;
  int neighbourhood_matches = 0;
  int neighbour_pairs = 0;
  for (int position = 0; position < kNeighbourhoodSize; ++position) {
    const int left_neighbour = stats.left_grid.neighbour(left, position);
    const int right_neighbour =
        stats.right_grid.neighbour(right, rotatedPosition(position, rotation));
    if (left_neighbour == kNoCell || right_neighbour == kNoCell) continue;
    support += stats.pairSizeOf(left_neighbour, right_neighbour);
    neighbourhood_matches += stats.matches_in_left_cell[left_neighbour];
    ++neighbour_pairs;
  }
  // The centre pair always exists and holds at least one match, so tau > 0.
  const double tau =
      threshold_factor * std::sqrt(static_cast<double>(neighbourhood_matches) / neighbour_pairs);
  return support / tau;
}

/// Raises each match's score to S / tau of its cell pair when it lies in its left cell's best
/// pair; other matches are not assigned in this run.
void scoreRun(const MotionStatistics& stats, int rotation, double threshold_factor,
              std::vector<double>* scores) {
  std::vector<double> cell_score(stats.left_grid.cellCount(), 0.0);
  for (int left = 0; left < stats.left_grid.cellCount(); ++left) {
    if (stats.best_right_cell[left] != kNoCell) {
      cell_score[left] = pairScore(stats, left, rotation, threshold_factor);
    }
  }
  for (size_t i = 0; i < scores->size(); ++i) {
    const int left = stats.left_cell[i];
    if (left != kNoCell && stats.right_cell[i] == stats.best_right_cell[left]) {
      (*scores)[i] = std::max((*scores)[i], cell_score[left]);
    }
  }
}

size_t countKept(const std::vector<double>& scores) {
  return static_cast<size_t>(
      std::count_if(scores.begin(), scores.end(), [](double score) { return score > 1.0; }));
}

Grid scaledGrid(const Grid& grid, double scale) {
  return {std::max(1, static_cast<int>(std::lround(grid.cols * scale))),
          std::max(1, static_cast<int>(std::lround(grid.rows * scale)))};
}

/// Scores of the rotation and right-grid scale that keep the most matches.
std::vector<double> bestScores(const std::vector<NormalisedMatch>& matches,
                               const GmsConfig& config) {
  const Grid left_grid{config.grid_cells, config.grid_cells};
  const size_t scale_count = config.with_scale ? kRightGridScales.size() : 1;
  const int rotation_count = config.with_rotation ? kRotationCount : 1;
  std::vector<double> best(matches.size(), 0.0);
  size_t best_kept = 0;
  for (size_t scale = 0; scale < scale_count; ++scale) {
    const Grid right_grid = scaledGrid(left_grid, kRightGridScales[scale]);
    std::vector<MotionStatistics> runs;
    for (int shift = 0; shift < kShiftCount; ++shift) {
      runs.push_back(countMotion(matches, left_grid, right_grid, shift));
    }
    for (int rotation = 0; rotation < rotation_count; ++rotation) {
      std::vector<double> scores(matches.size(), 0.0);
      for (const MotionStatistics& run : runs) {
        scoreRun(run, rotation, config.threshold_factor, &scores);
      }
      const size_t kept = countKept(scores);
      if ((scale == 0 && rotation == 0) || kept > best_kept) {
        best = std::move(scores);
        best_kept = kept;
      }
    }
  }
  return best;
}

void validateImageSize(const cv::Size& size, const std::string& which) {
  if (size.width <= 0 || size.height <= 0) {
    throw std::invalid_argument("filterGms: " + which + " must be positive, got " +
                                std::to_string(size.width) + "x" + std::to_string(size.height));
  }
}

}  // namespace

FilterResult filterGms(const PutativeMatches& input, const GmsConfig& config) {
  validate(config);
  FilterResult result;
  if (input.matches.empty()) return result;  // no grid needed, so image sizes are not checked
  validateImageSize(input.left_image_size, "left_image_size");
  validateImageSize(input.right_image_size, "right_image_size");
  checkKeypointIndices(input);

  const std::vector<NormalisedMatch> matches = normaliseMatches(input);
  result.score = bestScores(matches, config);
  result.keep.resize(matches.size());
  for (size_t i = 0; i < matches.size(); ++i) {
    if (!input.hasFinitePositions(i)) {
      result.score[i] = std::numeric_limits<double>::quiet_NaN();
    }
    result.keep[i] = result.score[i] > 1.0;  // false for NaN
  }
  return result;
}

}  // namespace sift_hull
