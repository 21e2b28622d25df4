// The 3-D side of the "views" silhouettes (hull/view_prior.h).

#include "hull/view_prior.h"

#include <Eigen/Eigenvalues>
#include <algorithm>
#include <cmath>
#include <mutex>
#include <opencv2/core/utility.hpp>
#include <opencv2/imgproc.hpp>
#include <unordered_map>
#include <unordered_set>

namespace sift_hull {
namespace view_prior {
namespace {

struct Grid {
  Eigen::Vector3d origin;
  double cell = 0.0;
  int nx = 0, ny = 0, nz = 0;
  Eigen::Vector3d centre(int x, int y, int z) const {
    return origin + cell * Eigen::Vector3d(x + 0.5, y + 0.5, z + 0.5);
  }
};

Grid gridOver(const Box3d& box, int cells) {
  Grid grid;
  grid.cell = box.size().maxCoeff() / cells;
  grid.origin = box.min_W;
  const Eigen::Vector3d size = box.size();
  grid.nx = std::max(1, static_cast<int>(std::ceil(size.x() / grid.cell)));
  grid.ny = std::max(1, static_cast<int>(std::ceil(size.y() / grid.cell)));
  grid.nz = std::max(1, static_cast<int>(std::ceil(size.z() / grid.cell)));
  return grid;
}

/// A cell centre's grid index relative to the cell centre `origin`.
Eigen::Vector3i cellIndex(const Eigen::Vector3d& origin, double cell, const Eigen::Vector3d& c) {
  const Eigen::Vector3d i = (c - origin) / cell;
  return {static_cast<int>(std::lround(i.x())), static_cast<int>(std::lround(i.y())),
          static_cast<int>(std::lround(i.z()))};
}

/// One key per grid index within 4096 cells of the origin.
int64_t cellKey(const Eigen::Vector3i& i) {
  return ((int64_t{i.x()} + 4096) << 26) | ((int64_t{i.y()} + 4096) << 13) | (i.z() + 4096);
}

}  // namespace

CoarseHull carve(const std::vector<cv::Mat>& masks, const std::vector<PinholeCamera>& cameras,
                 const PixelScale& scale, const Box3d& box, int cells, int tolerated) {
  const Grid grid = gridOver(box, cells);
  CoarseHull hull;
  hull.cell = grid.cell;
  std::mutex mutex;
  cv::parallel_for_(cv::Range(0, grid.nz), [&](const cv::Range& range) {
    std::vector<Eigen::Vector3d> kept;
    for (int z = range.start; z < range.end; ++z) {
      for (int y = 0; y < grid.ny; ++y) {
        for (int x = 0; x < grid.nx; ++x) {
          const Eigen::Vector3d X = grid.centre(x, y, z);
          int against = 0, seen = 0;
          for (size_t v = 0; v < cameras.size() && against <= tolerated; ++v) {
            if (!(cameras[v].depth(X) > 0.0)) continue;
            const Eigen::Vector2d p = scale(cameras[v].project(X));
            const int u = static_cast<int>(std::lround(p.x()));
            const int w = static_cast<int>(std::lround(p.y()));
            if (u < 0 || w < 0 || u >= masks[v].cols || w >= masks[v].rows) continue;
            ++seen;
            against += masks[v].at<uint8_t>(w, u) == 0;
          }
          if (against <= tolerated && seen >= 2) kept.push_back(X);
        }
      }
    }
    const std::lock_guard<std::mutex> lock(mutex);
    hull.centres_W.insert(hull.centres_W.end(), kept.begin(), kept.end());
  });
  return hull;
}

Box3d boxOf(const CoarseHull& hull, double margin_cells) {
  Box3d box;
  if (hull.centres_W.empty()) return box;
  box.min_W = box.max_W = hull.centres_W.front();
  for (const Eigen::Vector3d& c : hull.centres_W) {
    box.min_W = box.min_W.cwiseMin(c);
    box.max_W = box.max_W.cwiseMax(c);
  }
  const double margin = (0.5 + margin_cells) * hull.cell;
  box.min_W.array() -= margin;
  box.max_W.array() += margin;
  return box;
}

Eigen::Vector3d meanUp(const std::vector<PinholeCamera>& cameras) {
  Eigen::Vector3d up = Eigen::Vector3d::Zero();
  for (const PinholeCamera& camera : cameras) {
    // The image's y axis points down; its sign follows the camera's handedness.
    const double hand = camera.improper() ? -1.0 : 1.0;
    up -= hand * camera.R().row(1).transpose();
  }
  if (!(up.norm() > 1e-9)) return Eigen::Vector3d::UnitZ();
  up.normalize();
  // Cameras held level (no roll) have horizontal image x axes: up is the direction most nearly
  // orthogonal to all of them, when they span a plane (the smallest of the scatter's eigenvalues
  // under a hundredth of the others'), with the mean's sign.
  Eigen::Matrix3d scatter = Eigen::Matrix3d::Zero();
  for (const PinholeCamera& camera : cameras) {
    const Eigen::Vector3d x = camera.R().row(0).transpose();
    scatter += x * x.transpose();
  }
  const Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> solver(scatter);
  const Eigen::Vector3d values = solver.eigenvalues();  // ascending
  if (values(0) < 0.01 * values(1)) {
    Eigen::Vector3d level = solver.eigenvectors().col(0);
    if (level.dot(up) < 0.0) level = -level;
    if (level.dot(up) > std::cos(20.0 * M_PI / 180.0)) return level;
  }
  return up;
}

void keepLargestPart(CoarseHull* hull) {
  if (hull->centres_W.empty()) return;
  const Eigen::Vector3d origin = hull->centres_W.front();
  const auto index = [&](const Eigen::Vector3d& c) { return cellIndex(origin, hull->cell, c); };
  std::unordered_map<int64_t, size_t> cells;
  for (size_t k = 0; k < hull->centres_W.size(); ++k) cells[cellKey(index(hull->centres_W[k]))] = k;
  std::vector<int> part(hull->centres_W.size(), -1);
  std::vector<size_t> sizes;
  for (size_t seed = 0; seed < part.size(); ++seed) {
    if (part[seed] >= 0) continue;
    const int id = static_cast<int>(sizes.size());
    sizes.push_back(0);
    std::vector<size_t> stack{seed};
    part[seed] = id;
    while (!stack.empty()) {
      const size_t k = stack.back();
      stack.pop_back();
      ++sizes.back();
      const Eigen::Vector3i i = index(hull->centres_W[k]);
      for (int dx = -1; dx <= 1; ++dx) {
        for (int dy = -1; dy <= 1; ++dy) {
          for (int dz = -1; dz <= 1; ++dz) {
            const auto found = cells.find(cellKey(i + Eigen::Vector3i(dx, dy, dz)));
            if (found == cells.end() || part[found->second] >= 0) continue;
            part[found->second] = id;
            stack.push_back(found->second);
          }
        }
      }
    }
  }
  const int largest =
      static_cast<int>(std::max_element(sizes.begin(), sizes.end()) - sizes.begin());
  std::vector<Eigen::Vector3d> kept;
  kept.reserve(sizes[static_cast<size_t>(largest)]);
  for (size_t k = 0; k < part.size(); ++k) {
    if (part[k] == largest) kept.push_back(hull->centres_W[k]);
  }
  hull->centres_W = std::move(kept);
}

double cutSupport(const Eigen::Vector3d& up, CoarseHull* hull, double* height) {
  *height = 0.0;
  const size_t before = hull->centres_W.size();
  if (before < 64) return 0.0;
  double low = std::numeric_limits<double>::infinity(), high = -low;
  for (const Eigen::Vector3d& c : hull->centres_W) {
    low = std::min(low, up.dot(c));
    high = std::max(high, up.dot(c));
  }
  const int layers = static_cast<int>(std::floor((high - low) / hull->cell)) + 1;
  const auto layerOf = [&](const Eigen::Vector3d& c) {
    return std::clamp(static_cast<int>(std::floor((up.dot(c) - low) / hull->cell + 0.5)), 0,
                      layers - 1);
  };
  // Cells in the plane across `up`, keyed by their rounded coordinates there.
  const Eigen::Vector3d e1 = up.unitOrthogonal(), e2 = up.cross(e1);
  const auto key = [&](const Eigen::Vector3d& c, int dx, int dy) {
    const int64_t x = std::llround(e1.dot(c) / hull->cell) + dx + (1 << 20);
    const int64_t y = std::llround(e2.dot(c) / hull->cell) + dy + (1 << 20);
    return (x << 22) | y;
  };
  std::vector<std::vector<const Eigen::Vector3d*>> by_layer(static_cast<size_t>(layers));
  for (const Eigen::Vector3d& c : hull->centres_W) {
    by_layer[static_cast<size_t>(layerOf(c))].push_back(&c);
  }
  // The share of a layer's cells outside the footprint of the five layers above it, grown by two
  // cells: what stands there does not cover it.
  constexpr int kAbove = 5, kGrow = 2;
  const auto uncovered = [&](int layer) {
    std::unordered_set<int64_t> footprint;
    for (int l = layer + 1; l <= layer + kAbove && l < layers; ++l) {
      for (const Eigen::Vector3d* cell : by_layer[static_cast<size_t>(l)]) {
        for (int dx = -kGrow; dx <= kGrow; ++dx) {
          for (int dy = -kGrow; dy <= kGrow; ++dy) footprint.insert(key(*cell, dx, dy));
        }
      }
    }
    size_t outside = 0;
    for (const Eigen::Vector3d* cell : by_layer[static_cast<size_t>(layer)]) {
      outside += footprint.count(key(*cell, 0, 0)) == 0;
    }
    return outside;
  };
  // The support's top: the widest layer of the lower half, when a third of it, and 1 % of the
  // hull, lies uncovered. Below it lies what the support hides from every camera above it; the
  // layers above it that are still that wide (its thickness, up to a tenth of the height) go too.
  int widest = 0;
  for (int l = 1; l <= layers / 2; ++l) {
    if (by_layer[static_cast<size_t>(l)].size() > by_layer[static_cast<size_t>(widest)].size()) {
      widest = l;
    }
  }
  const auto isSupport = [&](int layer) {
    const size_t outside = uncovered(layer);
    return 3 * outside >= by_layer[static_cast<size_t>(layer)].size() && outside * 100 >= before;
  };
  // A support has a thickness: its top is the last layer above the widest still 0.8 as wide.
  const size_t wide = by_layer[static_cast<size_t>(widest)].size();
  int top = widest;
  while (top + 1 < layers && 5 * by_layer[static_cast<size_t>(top + 1)].size() >= 4 * wide) ++top;
  int cut = 0;
  if (top + kAbove < layers && top - widest <= std::max(2, layers / 10) && isSupport(top)) {
    cut = top + 1;
  }
  if (cut == 0) return 0.0;
  hull->centres_W.erase(std::remove_if(hull->centres_W.begin(), hull->centres_W.end(),
                                       [&](const Eigen::Vector3d& c) { return layerOf(c) < cut; }),
                        hull->centres_W.end());
  *height = cut * hull->cell;
  return 1.0 - static_cast<double>(hull->centres_W.size()) / static_cast<double>(before);
}

cv::Mat project(const CoarseHull& hull, const PinholeCamera& camera, const PixelScale& scale,
                cv::Size size) {
  cv::Mat mask = cv::Mat::zeros(size, CV_8UC1);
  if (hull.centres_W.empty()) return mask;
  // Surface cells: those with an empty face neighbour. Cells are keyed by their grid index
  // relative to the first cell.
  const Eigen::Vector3d origin = hull.centres_W.front();
  const auto key = [&](const Eigen::Vector3d& c) {
    return cellKey(cellIndex(origin, hull.cell, c));
  };
  std::unordered_set<int64_t> cells;
  cells.reserve(hull.centres_W.size() * 2);
  for (const Eigen::Vector3d& c : hull.centres_W) cells.insert(key(c));
  const double focal = std::abs(camera.K()(0, 0)) * scale.sx;
  static const int kFaces[6][3] = {{1, 0, 0},  {-1, 0, 0}, {0, 1, 0},
                                   {0, -1, 0}, {0, 0, 1},  {0, 0, -1}};
  for (const Eigen::Vector3d& c : hull.centres_W) {
    bool surface = false;
    for (const auto& f : kFaces) {
      surface = surface || !cells.count(key(c + hull.cell * Eigen::Vector3d(f[0], f[1], f[2])));
    }
    const double depth = camera.depth(c);
    if (!surface || !(depth > 0.0)) continue;
    const Eigen::Vector2d p = scale(camera.project(c));
    const double radius = 0.9 * focal * hull.cell / depth;
    if (p.x() < -radius || p.y() < -radius || p.x() > size.width + radius ||
        p.y() > size.height + radius) {
      continue;
    }
    cv::circle(
        mask, cv::Point(static_cast<int>(std::lround(p.x())), static_cast<int>(std::lround(p.y()))),
        std::max(1, static_cast<int>(std::ceil(radius))), cv::Scalar(255), cv::FILLED);
  }
  cv::morphologyEx(mask, mask, cv::MORPH_CLOSE,
                   cv::getStructuringElement(cv::MORPH_ELLIPSE, cv::Size(5, 5)));
  return mask;
}

}  // namespace view_prior
}  // namespace sift_hull
