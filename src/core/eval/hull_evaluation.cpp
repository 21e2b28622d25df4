#include "sift_hull/eval/hull_evaluation.h"

#include <algorithm>
#include <atomic>
#include <cmath>
#include <opencv2/core.hpp>
#include <stdexcept>
#include <thread>

#include "common/parallel.h"
#include "sift_hull/eval/mesh_render.h"

namespace sift_hull {
namespace {

void carveSlice(const std::vector<HullView>& views, int k, DenseGrid* grid) {
  for (int j = 0; j < grid->cells; ++j) {
    for (int i = 0; i < grid->cells; ++i) {
      const Eigen::Vector3d centre = grid->centre(i, j, k);
      const bool kept = std::all_of(views.begin(), views.end(),
                                    [&](const HullView& view) { return view.keeps(centre); });
      grid->occupied[grid->index(i, j, k)] = kept;
    }
  }
}

/// The camera whose pixel (u, v) is `camera`'s pixel (step u, step v).
PinholeCamera sampledCamera(const PinholeCamera& camera, int step) {
  const Eigen::Matrix3d K =
      Eigen::DiagonalMatrix<double, 3>(1.0 / step, 1.0 / step, 1.0) * camera.K();
  const PinholeCamera proper = camera.improper()
                                   ? PinholeCamera(K, -camera.R(), -camera.t()).negated()
                                   : PinholeCamera(K, camera.R(), camera.t());
  return proper.withDistortion(camera.distortion());
}

}  // namespace

double maskIoU(const cv::Mat& a, const cv::Mat& b) {
  if (a.size() != b.size()) throw std::invalid_argument("maskIoU: masks differ in size");
  const int intersection = cv::countNonZero((a != 0) & (b != 0));
  const int union_count = cv::countNonZero((a != 0) | (b != 0));
  return union_count == 0 ? 1.0 : static_cast<double>(intersection) / union_count;
}

ReprojectionIoU reprojectionIoU(const TriangleMesh& mesh, const std::vector<HullView>& views,
                                int threads, size_t max_samples_per_view, bool closed) {
  ReprojectionIoU result;
  result.per_view.assign(views.size(), 0.0);
  requireValidFaces(mesh, "reprojectionIoU");
  std::vector<int> steps(views.size(), 1);
  detail::parallelFor(views.size(), std::max(1, threads), [&](size_t i) {
    const HullView& view = views[i];
    const cv::Size size = view.imageSize();
    int step = 1;
    while (max_samples_per_view > 0 &&
           static_cast<size_t>((size.width + step - 1) / step) *
                   static_cast<size_t>((size.height + step - 1) / step) >
               max_samples_per_view) {
      ++step;
    }
    steps[i] = step;
    if (step == 1) {
      result.per_view[i] =
          maskIoU(rasteriseMask(mesh, view.camera(), size, closed, true), view.mask());
      return;
    }
    const cv::Size sampled((size.width + step - 1) / step, (size.height + step - 1) / step);
    const cv::Mat full = view.mask();
    cv::Mat mask(sampled, CV_8UC1);
    for (int v = 0; v < sampled.height; ++v) {
      const uchar* in = full.ptr<uchar>(v * step);
      uchar* out = mask.ptr<uchar>(v);
      for (int u = 0; u < sampled.width; ++u) out[u] = in[u * step];
    }
    result.per_view[i] = maskIoU(
        rasteriseMask(mesh, sampledCamera(view.camera(), step), sampled, closed, true), mask);
  });
  if (!steps.empty()) result.sample_step_px = *std::max_element(steps.begin(), steps.end());
  if (result.per_view.empty()) return result;
  result.min = *std::min_element(result.per_view.begin(), result.per_view.end());
  double sum = 0.0;
  for (double iou : result.per_view) sum += iou;
  result.mean = sum / result.per_view.size();
  return result;
}

size_t DenseGrid::occupiedCount() const {
  return static_cast<size_t>(std::count(occupied.begin(), occupied.end(), uint8_t{1}));
}

Box3d DenseGrid::occupiedBounds() const {
  Eigen::Vector3i low = Eigen::Vector3i::Constant(cells), high = Eigen::Vector3i::Constant(-1);
  for (int k = 0; k < cells; ++k) {
    for (int j = 0; j < cells; ++j) {
      for (int i = 0; i < cells; ++i) {
        if (!occupied[index(i, j, k)]) continue;
        low = low.cwiseMin(Eigen::Vector3i(i, j, k));
        high = high.cwiseMax(Eigen::Vector3i(i, j, k));
      }
    }
  }
  Box3d box;
  if (high.x() < 0) return box;
  box.min_W = origin_W + low.cast<double>() * voxel_m;
  box.max_W = origin_W + (high + Eigen::Vector3i::Ones()).cast<double>() * voxel_m;
  return box;
}

DenseGrid denseCarving(const std::vector<HullView>& views, const Box3d& cube, int cells,
                       int threads) {
  DenseGrid grid;
  grid.origin_W = cube.min_W;
  grid.voxel_m = cube.size().maxCoeff() / cells;
  grid.cells = cells;
  grid.occupied.assign(static_cast<size_t>(cells) * cells * cells, 0);
  detail::parallelFor(static_cast<size_t>(cells), threads,
                      [&](size_t k) { carveSlice(views, static_cast<int>(k), &grid); });
  return grid;
}

bool hullHolds(const VisualHull& hull, const Eigen::Vector3d& X_W) {
  const CellState state = hull.leafAt(X_W).state;
  return state == CellState::kIn || (state == CellState::kSurface && hull.valueAt(X_W) <= 0.0f);
}

namespace {

/// A point of cell n, the same on every call: offsets in [0, 1) per axis from a SplitMix64 hash
/// of n, so that a sample's place in its cell does not repeat from cell to cell.
Eigen::Vector3d jitterInCell(size_t n) {
  Eigen::Vector3d offset;
  uint64_t state = static_cast<uint64_t>(n) * 3u;
  for (int axis = 0; axis < 3; ++axis) {
    uint64_t z = (state += 0x9e3779b97f4a7c15ull);
    z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9ull;
    z = (z ^ (z >> 27)) * 0x94d049bb133111ebull;
    z ^= z >> 31;
    offset[axis] = static_cast<double>(z >> 11) * 0x1.0p-53;
  }
  return offset;
}

}  // namespace

SolidSamples sampleAgainstSolid(const VisualHull& hull, const SolidPredicate& inside, int per_axis,
                                const SolidPredicate& cavities) {
  if (per_axis < 1) throw std::invalid_argument("sampleAgainstSolid: per_axis must be >= 1");
  SolidSamples samples;
  samples.per_axis = per_axis;
  const double cell_m = hull.cube().edge_m() / per_axis;
  samples.cell_m3 = cell_m * cell_m * cell_m;
  const size_t count = static_cast<size_t>(per_axis) * per_axis * per_axis;
  samples.truth.resize(count);
  samples.hull.resize(count);
  if (cavities) samples.cavity.resize(count);
  const Eigen::Vector3d origin_W = hull.cube().origin_W();
  for (size_t n = 0; n < count; ++n) {
    const Eigen::Vector3d cell(static_cast<double>(n % per_axis),
                               static_cast<double>(n / per_axis % per_axis),
                               static_cast<double>(n / per_axis / per_axis));
    const Eigen::Vector3d X_W = origin_W + (cell + jitterInCell(n)) * cell_m;
    samples.truth[n] = inside(X_W) ? 1 : 0;
    samples.hull[n] = hullHolds(hull, X_W) ? 1 : 0;
    if (cavities) samples.cavity[n] = cavities(X_W) ? 1 : 0;
  }
  return samples;
}

SolidComparison compareWithSolid(const SolidSamples& samples) {
  size_t both = 0, hull = 0, truth = 0, cavity = 0, cavity_filled = 0;
  for (size_t n = 0; n < samples.truth.size(); ++n) {
    both += samples.truth[n] && samples.hull[n];
    hull += samples.hull[n];
    truth += samples.truth[n];
    if (!samples.cavity.empty()) {
      cavity += samples.cavity[n];
      cavity_filled += samples.cavity[n] && samples.hull[n];
    }
  }
  SolidComparison comparison;
  comparison.cavity_m3 = cavity * samples.cell_m3;
  comparison.cavity_filled_m3 = cavity_filled * samples.cell_m3;
  comparison.hull_m3 = hull * samples.cell_m3;
  comparison.truth_m3 = truth * samples.cell_m3;
  comparison.excess_m3 = (hull - both) * samples.cell_m3;
  comparison.missing_m3 = (truth - both) * samples.cell_m3;
  const size_t either = hull + truth - both;
  comparison.iou = either == 0 ? 1.0 : static_cast<double>(both) / either;
  return comparison;
}

double falseCarvedFraction(const SolidSamples& before, const SolidSamples& after) {
  if (before.per_axis != after.per_axis || before.truth != after.truth) {
    throw std::invalid_argument("falseCarvedFraction: the samplings differ");
  }
  size_t carved = 0, truth = 0;
  for (size_t n = 0; n < before.truth.size(); ++n) {
    truth += before.truth[n];
    carved += before.truth[n] && before.hull[n] && !after.hull[n];
  }
  return truth == 0 ? 0.0 : static_cast<double>(carved) / truth;
}

double volumeIoU(const VisualHull& hull, const DenseGrid& dense) {
  size_t both = 0, either = 0;
  for (int k = 0; k < dense.cells; ++k) {
    for (int j = 0; j < dense.cells; ++j) {
      for (int i = 0; i < dense.cells; ++i) {
        const Eigen::Vector3d centre = dense.centre(i, j, k);
        const bool in_hull = hullHolds(hull, centre);
        const bool in_dense = dense.occupied[dense.index(i, j, k)];
        both += in_hull && in_dense;
        either += in_hull || in_dense;
      }
    }
  }
  return either == 0 ? 1.0 : static_cast<double>(both) / either;
}

double meanDistanceToSphere(const TriangleMesh& mesh, const Eigen::Vector3d& centre_W,
                            double radius_m) {
  if (mesh.vertices_W.empty()) return 0.0;
  double sum = 0.0;
  for (const Eigen::Vector3f& vertex : mesh.vertices_W) {
    sum += std::abs((vertex.cast<double>() - centre_W).norm() - radius_m);
  }
  return sum / mesh.vertices_W.size();
}

}  // namespace sift_hull
