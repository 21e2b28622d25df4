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

}  // namespace

SpatialNeighbours::SpatialNeighbours(const std::vector<cv::Point2f>& points, size_t k)
    : k_(k), neighbours_(points.size() * k, -1) {
  if (k == 0 || points.empty()) return;
  const Grid grid = makeGrid(points, k);
  const int max_ring = std::max(grid.columns, grid.rows);
  Nearest nearest(k);
  for (size_t i = 0; i < points.size(); ++i) {
    if (!finite(points[i])) continue;
    nearest.clear();
    const int cx = grid.cellX(points[i].x), cy = grid.cellY(points[i].y);
    for (int ring = 0; ring <= max_ring; ++ring) {
      offerRing(grid, points, static_cast<int>(i), cx, cy, ring, &nearest);
      // Points beyond this ring lie outside the block of cells searched so far.
      const float x0 = grid.min_x + (cx - ring) * grid.cell,
                  y0 = grid.min_y + (cy - ring) * grid.cell;
      const float side = (2 * ring + 1) * grid.cell;
      const float reach = std::min(std::min(points[i].x - x0, x0 + side - points[i].x),
                                   std::min(points[i].y - y0, y0 + side - points[i].y));
      if (nearest.full() && nearest.worst() < reach * reach) break;
    }
    for (size_t n = 0; n < nearest.items().size(); ++n) {
      neighbours_[i * k + n] = nearest.items()[n].second;
    }
  }
}

}  // namespace sift_hull
