#include "sift_hull/filters/spatial_neighbours.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <utility>

namespace sift_hull {
namespace {

/// Points bucketed in square cells of a grid over their bounding box.
struct Grid {
  float min_x = 0, min_y = 0, cell = 1;
  int columns = 1, rows = 1;
  std::vector<int> start;  ///< cell c's points are order[start[c] .. start[c + 1])
  std::vector<int> order;  ///< point indices sorted by cell
  int cellX(float x) const { return std::clamp(int((x - min_x) / cell), 0, columns - 1); }
  int cellY(float y) const { return std::clamp(int((y - min_y) / cell), 0, rows - 1); }
};

bool finite(const cv::Point2f& p) { return std::isfinite(p.x) && std::isfinite(p.y); }

/// A grid of about k / 2 points per cell (at least one cell, at most about 4 N cells).
Grid makeGrid(const std::vector<cv::Point2f>& points, size_t k) {
  Grid grid;
  float max_x = -std::numeric_limits<float>::infinity(), max_y = max_x;
  grid.min_x = grid.min_y = std::numeric_limits<float>::infinity();
  size_t count = 0;
  for (const cv::Point2f& p : points) {
    if (!finite(p)) continue;
    ++count;
    grid.min_x = std::min(grid.min_x, p.x), grid.min_y = std::min(grid.min_y, p.y);
    max_x = std::max(max_x, p.x), max_y = std::max(max_y, p.y);
  }
  if (count == 0) return grid;
  const double width = std::max(1e-3, double(max_x) - grid.min_x);
  const double height = std::max(1e-3, double(max_y) - grid.min_y);
  const double cells = std::clamp(2.0 * count / std::max<size_t>(k, 1), 1.0, 4.0 * count);
  grid.cell = static_cast<float>(std::sqrt(width * height / cells));
  grid.cell = std::max(grid.cell, static_cast<float>(std::max(width, height) / 4096.0));
  grid.columns = std::max(1, int(std::ceil(width / grid.cell)));
  grid.rows = std::max(1, int(std::ceil(height / grid.cell)));
  std::vector<int> cell_of(points.size(), -1);
  grid.start.assign(size_t(grid.columns) * grid.rows + 1, 0);
  for (size_t i = 0; i < points.size(); ++i) {
    if (!finite(points[i])) continue;
    cell_of[i] = grid.cellY(points[i].y) * grid.columns + grid.cellX(points[i].x);
    ++grid.start[cell_of[i] + 1];
  }
  for (size_t c = 1; c < grid.start.size(); ++c) grid.start[c] += grid.start[c - 1];
  grid.order.resize(count);
  std::vector<int> fill(grid.start.begin(), grid.start.end() - 1);
  for (size_t i = 0; i < points.size(); ++i) {
    if (cell_of[i] >= 0) grid.order[fill[cell_of[i]]++] = static_cast<int>(i);
  }
  return grid;
}

/// The k nearest candidates so far, sorted by (squared distance, index).
class Nearest {
 public:
  explicit Nearest(size_t k) : k_(k) { items_.reserve(k + 1); }
  void clear() { items_.clear(); }
  bool full() const { return items_.size() == k_; }
  float worst() const { return items_.back().first; }
  void offer(float d2, int j) {
    const std::pair<float, int> item(d2, j);
    if (full() && !(item < items_.back())) return;
    auto at = std::upper_bound(items_.begin(), items_.end(), item);
    items_.insert(at, item);
    if (items_.size() > k_) items_.pop_back();
  }
  const std::vector<std::pair<float, int>>& items() const { return items_; }

 private:
  size_t k_;
  std::vector<std::pair<float, int>> items_;
};

/// Offers the points of the cells at Chebyshev distance `ring` from (cx, cy).
void offerRing(const Grid& grid, const std::vector<cv::Point2f>& points, int i, int cx, int cy,
               int ring, Nearest* nearest) {
  const cv::Point2f& p = points[i];
  for (int y = std::max(0, cy - ring); y <= std::min(grid.rows - 1, cy + ring); ++y) {
    const bool edge_row = y == cy - ring || y == cy + ring;
    const int step = (edge_row || ring == 0) ? 1 : 2 * ring;
    for (int x = cx - ring; x <= cx + ring; x += step) {
      if (x < 0 || x >= grid.columns) continue;
      const int c = y * grid.columns + x;
      for (int s = grid.start[c]; s < grid.start[c + 1]; ++s) {
        const int j = grid.order[s];
        const float dx = points[j].x - p.x, dy = points[j].y - p.y;
        if (j != i) nearest->offer(dx * dx + dy * dy, j);
      }
    }
  }
}

/// How far point p is from the outside of the block of cells within Chebyshev distance `ring` of
/// its cell (cx, cy): no unseen point is nearer. Sides at the grid's edge have nothing beyond.
float reach(const Grid& grid, const cv::Point2f& p, int cx, int cy, int ring) {
  constexpr float kFar = std::numeric_limits<float>::infinity();
  const float x0 = grid.min_x + (cx - ring) * grid.cell, y0 = grid.min_y + (cy - ring) * grid.cell;
  const float side = (2 * ring + 1) * grid.cell;
  const float left = cx - ring <= 0 ? kFar : p.x - x0;
  const float right = cx + ring >= grid.columns - 1 ? kFar : x0 + side - p.x;
  const float top = cy - ring <= 0 ? kFar : p.y - y0;
  const float bottom = cy + ring >= grid.rows - 1 ? kFar : y0 + side - p.y;
  return std::min(std::min(left, right), std::min(top, bottom));
}

/// The general search, ring after ring, for the points the 3x3 block does not settle.
void ringSearch(const Grid& grid, const std::vector<cv::Point2f>& points, int i, Nearest* nearest) {
  nearest->clear();
  const int cx = grid.cellX(points[i].x), cy = grid.cellY(points[i].y);
  const int max_ring = std::max(grid.columns, grid.rows);
  for (int ring = 0; ring <= max_ring; ++ring) {
    offerRing(grid, points, i, cx, cy, ring, nearest);
    const float r = reach(grid, points[i], cx, cy, ring);
    if (nearest->full() && nearest->worst() < r * r) break;
  }
}

/// The points of the 3x3 block of cells around (cx, cy).
void gatherBlock(const Grid& grid, int cx, int cy, std::vector<int>* block) {
  block->clear();
  for (int y = std::max(0, cy - 1); y <= std::min(grid.rows - 1, cy + 1); ++y) {
    for (int x = std::max(0, cx - 1); x <= std::min(grid.columns - 1, cx + 1); ++x) {
      const int c = y * grid.columns + x;
      block->insert(block->end(), grid.order.begin() + grid.start[c],
                    grid.order.begin() + grid.start[c + 1]);
    }
  }
}

}  // namespace

namespace {

/// The k nearest of a block's candidates (squared distances d2, indices), by (d2, index): the
/// k-th smallest distance by selection on plain floats, then the candidates up to it.
void selectNearest(const std::vector<float>& d2, const std::vector<int>& index, size_t k,
                   std::vector<float>* scratch, std::vector<std::pair<float, int>>* chosen) {
  chosen->clear();
  if (k >= d2.size()) {
    for (size_t j = 0; j < d2.size(); ++j) chosen->emplace_back(d2[j], index[j]);
  } else {
    scratch->assign(d2.begin(), d2.end());
    std::nth_element(scratch->begin(), scratch->begin() + (k - 1), scratch->end());
    const float kth = (*scratch)[k - 1];
    for (size_t j = 0; j < d2.size(); ++j) {
      if (d2[j] <= kth) chosen->emplace_back(d2[j], index[j]);
    }
  }
  std::sort(chosen->begin(), chosen->end());
  if (chosen->size() > k) chosen->resize(k);
}

}  // namespace

SpatialNeighbours::SpatialNeighbours(const std::vector<cv::Point2f>& points, size_t k)
    : k_(k), neighbours_(points.size() * k, -1) {
  if (k == 0 || points.empty()) return;
  const Grid grid = makeGrid(points, k);
  Nearest nearest(k);
  std::vector<int> block, others;
  std::vector<float> bx, by, d2, scratch;
  std::vector<std::pair<float, int>> chosen;
  for (int cy = 0; cy < grid.rows; ++cy) {
    for (int cx = 0; cx < grid.columns; ++cx) {
      const int c = cy * grid.columns + cx;
      if (grid.start[c] == grid.start[c + 1]) continue;
      gatherBlock(grid, cx, cy, &block);
      bx.resize(block.size()), by.resize(block.size());
      for (size_t b = 0; b < block.size(); ++b)
        bx[b] = points[block[b]].x, by[b] = points[block[b]].y;
      for (int s = grid.start[c]; s < grid.start[c + 1]; ++s) {
        const int i = grid.order[s];
        const cv::Point2f p = points[i];
        d2.clear(), others.clear();
        for (size_t b = 0; b < block.size(); ++b) {
          if (block[b] == i) continue;
          const float dx = bx[b] - p.x, dy = by[b] - p.y;
          d2.push_back(dx * dx + dy * dy), others.push_back(block[b]);
        }
        selectNearest(d2, others, k, &scratch, &chosen);
        const float r = reach(grid, p, cx, cy, 1);
        int* out = neighbours_.data() + size_t(i) * k;
        if (chosen.size() == k ? chosen.back().first < r * r : r == INFINITY) {
          for (size_t n = 0; n < chosen.size(); ++n) out[n] = chosen[n].second;
          continue;
        }
        ringSearch(grid, points, i, &nearest);
        for (size_t n = 0; n < nearest.items().size(); ++n) out[n] = nearest.items()[n].second;
      }
    }
  }
}

}  // namespace sift_hull
