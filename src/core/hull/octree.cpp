#include "sift_hull/hull/octree.h"

#include <algorithm>
#include <atomic>
#include <cmath>
#include <numeric>
#include <sstream>
#include <stdexcept>
#include <thread>

#include "common/parallel.h"
#include "hull/field_sampling.h"
#include "hull/octree_node.h"
#include "hull/voxel_key.h"
#include "sift_hull/hull/reduced_distance_map.h"
#include "sift_hull/limits.h"

namespace sift_hull {
namespace {
/// The edge, in finest voxels, of the tiles sampleField culls views in.
constexpr double kFieldTileVoxels = 8.0;
}  // namespace

namespace {

using detail::OctreeNode;

struct CellIndex {
  Eigen::Vector3i index = Eigen::Vector3i::Zero();
  int depth = 0;
};

CellIndex childOf(const CellIndex& cell, int child) {
  const Eigen::Vector3i offset((child >> 0) & 1, (child >> 1) & 1, (child >> 2) & 1);
  return {2 * cell.index + offset, cell.depth + 1};
}

/// A cell's centre in the views' local frame (HullView::useFrame): the cube is [-1, 1]^3.
Eigen::Vector3d localCentre(const CellIndex& cell) {
  const double cells = static_cast<double>(1 << cell.depth);
  return (cell.index.cast<double>() + Eigen::Vector3d::Constant(0.5)) * (2.0 / cells) -
         Eigen::Vector3d::Ones();
}

/// The local frame of a cube: its centre and half its edge.
Eigen::Vector3d frameOrigin(const HullCube& cube) {
  return cube.origin_W() + Eigen::Vector3d::Constant(0.5 * cube.edge_m());
}
double frameScale(const HullCube& cube) { return 0.5 * cube.edge_m(); }

using ViewList = std::vector<uint32_t>;

/// The children of a node whose update waits for the parallel pass, with the views to apply.
struct DeferredUpdate {
  OctreeNode* node;
  CellIndex cell;
  ViewList views;
};

/// Verdicts of a list of views on up to eight cells.
struct Verdicts {
  float values[8];
  uint32_t out_bits = 0;
  std::vector<uint8_t> in_bits;  ///< per view applied, bit c: cell c is all inside
  size_t applied = 0;            ///< views applied before every cell was out
};

/// Per-thread buffers by depth, reused from node to node: the walk is depth first, so a level's
/// buffers are free again once its node is done.
struct Scratch {
  std::vector<ViewList> views;     ///< [d]: the views applied to the node at depth d
  std::vector<Verdicts> verdicts;  ///< [d]: the verdicts on the children of the node at depth d

  static Scratch& forThread(int depths) {
    static thread_local Scratch scratch;
    if (scratch.views.size() < static_cast<size_t>(depths)) {
      scratch.views.resize(depths);
      scratch.verdicts.resize(depths);
    }
    return scratch;
  }
};

/// Updates nodes with a list of views: an out verdict prunes, an undecided verdict turns an in
/// cell into a surface cell split into children. A view that sees all of a cell inside its
/// silhouette sees its children inside too, so a node passes on to its children only the views
/// that did not: near the surface, a few of them. The centre value then is the maximum over the
/// views applied, which has the sign of f_iso (the views left out are negative there). The eight
/// children of a node are classified together, view by view.
class Refiner {
 public:
  Refiner(const HullCube& cube, const std::vector<HullView>& views,
          std::vector<DeferredUpdate>* deferred, int defer_depth)
      : cube_(cube), views_(views), deferred_(deferred), defer_depth_(defer_depth) {}

  void updateRoot(OctreeNode& root, size_t first_view) const {
    if (root.state == CellState::kOut || first_view == views_.size()) return;
    ViewList views(views_.size() - first_view);
    std::iota(views.begin(), views.end(), static_cast<uint32_t>(first_view));
    const Eigen::Vector3f centre = localCentre(CellIndex{}).cast<float>();
    Scratch& scratch = Scratch::forThread(cube_.depth + 2);
    Verdicts& verdicts = scratch.verdicts[0];
    classify({&centre.x(), &centre.y(), &centre.z(), 1}, 0, views, &verdicts);
    viewsNotIn(verdicts, views, 0, &scratch.views[0]);
    apply(root, CellIndex{}, verdictOf(verdicts, 0), verdicts.values[0], scratch.views[0]);
  }

  void updateChildren(OctreeNode& node, const CellIndex& cell, const ViewList& views) const {
    if (views.empty()) return;
    if (deferred_ != nullptr && cell.depth + 1 == defer_depth_) {
      deferred_->push_back({&node, cell, views});
      return;
    }
    float x[8], y[8], z[8];
    for (int c = 0; c < 8; ++c) {
      const Eigen::Vector3d centre = localCentre(childOf(cell, c));
      x[c] = static_cast<float>(centre.x());
      y[c] = static_cast<float>(centre.y());
      z[c] = static_cast<float>(centre.z());
    }
    Scratch& scratch = Scratch::forThread(cube_.depth + 2);
    Verdicts& verdicts = scratch.verdicts[cell.depth];
    classify({x, y, z, 8}, cell.depth + 1, views, &verdicts);
    ViewList& child_views = scratch.views[cell.depth + 1];
    for (int c = 0; c < 8; ++c) {
      OctreeNode& child = node.children[c];
      if (child.state == CellState::kOut) continue;
      viewsNotIn(verdicts, views, c, &child_views);
      apply(child, childOf(cell, c), verdictOf(verdicts, c), verdicts.values[c], child_views);
    }
  }

 private:
  static Verdict verdictOf(const Verdicts& verdicts, int cell) {
    if ((verdicts.out_bits >> cell) & 1) return Verdict::kOut;
    for (size_t k = 0; k < verdicts.applied; ++k) {
      if (!((verdicts.in_bits[k] >> cell) & 1)) return Verdict::kUndecided;
    }
    return Verdict::kIn;
  }

  static void viewsNotIn(const Verdicts& verdicts, const ViewList& views, int cell,
                         ViewList* not_in) {
    not_in->clear();
    for (size_t k = 0; k < verdicts.applied; ++k) {
      if (!((verdicts.in_bits[k] >> cell) & 1)) not_in->push_back(views[k]);
    }
  }

  void apply(OctreeNode& node, const CellIndex& cell, Verdict verdict, float value,
             const ViewList& views_not_in) const {
    if (verdict == Verdict::kOut) {
      node.state = CellState::kOut;
      node.children.reset();
      return;
    }
    node.centre_value = std::max(node.centre_value, value);
    if (verdict == Verdict::kUndecided && node.state == CellState::kIn) {
      node.state = CellState::kSurface;
      if (cell.depth == cube_.depth) return;
      // Children may be there already: free-space carving splits in cells (free_carving.cpp).
      if (!node.children) node.children = std::make_unique<OctreeNode[]>(8);
      updateChildren(node, cell, views_not_in);
    } else if (node.children) {
      updateChildren(node, cell, views_not_in);
    }
  }

  /// Applies the views in order, stopping once every cell is out.
  void classify(const PointBatch& centres, int depth, const ViewList& views,
                Verdicts* verdicts) const {
    // Half the cell's diagonal in local units (the cube's edge is 2).
    const float radius = static_cast<float>(std::sqrt(3.0) / (1 << depth));
    const uint32_t all = (uint32_t{1} << centres.count) - 1;
    std::fill(verdicts->values, verdicts->values + 8, -HullView::kFarOutside_px);
    verdicts->out_bits = 0;
    verdicts->in_bits.resize(views.size());
    verdicts->applied = 0;
    for (; verdicts->applied < views.size() && verdicts->out_bits != all; ++verdicts->applied) {
      uint32_t out = 0, in = 0;
      views_[views[verdicts->applied]].classifyBalls(centres, radius, verdicts->values, &out, &in);
      verdicts->out_bits |= out;
      verdicts->in_bits[verdicts->applied] = static_cast<uint8_t>(in);
    }
  }

  const HullCube& cube_;
  const std::vector<HullView>& views_;
  std::vector<DeferredUpdate>* deferred_;
  int defer_depth_;
};

/// A box so large that its finest voxel is wider than a camera's distance to it cannot hold a
/// hull the cameras resolve: throws std::invalid_argument.
void requireCameraOutsideVoxel(const HullView& view, const Eigen::Vector3d& centre_W,
                               double voxel_m) {
  const double distance_m = (view.camera().centre() - centre_W).norm();
  if (!(distance_m > voxel_m)) {
    std::ostringstream message;
    message << "view '" << view.name() << "': the box is too large for its camera: a voxel ("
            << voxel_m << " m) is wider than the camera's distance to the box centre ("
            << distance_m << " m); give a box around the object";
    throw std::invalid_argument(message.str());
  }
}

/// Depth of the cells the threads share out: 64 groups of eight balance two threads well.
constexpr int kParallelDepth = 3;

void visitLeaves(const OctreeNode& node, const CellIndex& cell,
                 const std::function<void(const HullCell&)>& visit) {
  if (!node.children) {
    visit({cell.index, cell.depth, node.state, node.centre_value});
    return;
  }
  for (int c = 0; c < 8; ++c) visitLeaves(node.children[c], childOf(cell, c), visit);
}

/// Whether a leaf below is in, or on the surface with its centre inside (HullStats' volume).
bool holdsOccupied(const OctreeNode& node) {
  if (!node.children) {
    return node.state == CellState::kIn ||
           (node.state == CellState::kSurface && node.centre_value <= 0.0f);
  }
  for (int c = 0; c < 8; ++c) {
    if (holdsOccupied(node.children[c])) return true;
  }
  return false;
}

size_t countSurfaceLeaves(const OctreeNode& node) {
  if (!node.children) return node.state == CellState::kSurface ? 1 : 0;
  size_t count = 0;
  for (int c = 0; c < 8; ++c) count += countSurfaceLeaves(node.children[c]);
  return count;
}

void collectSurfaceLeaves(const OctreeNode& node, const CellIndex& cell,
                          std::vector<Eigen::Vector3i>* cells) {
  if (!node.children) {
    if (node.state == CellState::kSurface) cells->push_back(cell.index);
    return;
  }
  for (int c = 0; c < 8; ++c) collectSurfaceLeaves(node.children[c], childOf(cell, c), cells);
}

}  // namespace

VisualHull::VisualHull(const Box3d& box, const HullConfig& config)
    : cube_(HullCube::forConfig(box, config)),
      config_(config),
      frame_origin_W_(frameOrigin(cube_)),
      frame_scale_(frameScale(cube_)),
      root_(std::make_unique<OctreeNode>()) {
  validate(config);
}

namespace {
void copyNode(const OctreeNode& from, OctreeNode* to) {
  to->state = from.state;
  to->centre_value = from.centre_value;
  if (!from.children) return;
  to->children = std::make_unique<OctreeNode[]>(8);
  for (int c = 0; c < 8; ++c) copyNode(from.children[c], &to->children[c]);
}
}  // namespace

VisualHull::VisualHull(const VisualHull& other, CloneTag)
    : cube_(other.cube_),
      config_(other.config_),
      frame_origin_W_(other.frame_origin_W_),
      frame_scale_(other.frame_scale_),
      views_(other.views_),
      root_(std::make_unique<OctreeNode>()),
      free_(other.free_) {
  copyNode(*other.root_, root_.get());
}

VisualHull VisualHull::clone() const { return VisualHull(*this, CloneTag{}); }

VisualHull::~VisualHull() = default;
VisualHull::VisualHull(VisualHull&&) noexcept = default;
VisualHull& VisualHull::operator=(VisualHull&&) noexcept = default;

void VisualHull::checkView(const HullView& view) const {
  HullView in_frame = view;
  in_frame.useFrame(frame_origin_W_, frame_scale_);
  requireCameraOutsideVoxel(view, frame_origin_W_, cube_.resolution_m);
}

void VisualHull::addViews(std::vector<HullView> views) {
  for (HullView& view : views) {
    view.useFrame(frame_origin_W_, frame_scale_);
    requireCameraOutsideVoxel(view, frame_origin_W_, cube_.resolution_m);
  }
  const size_t first_new = views_.size();
  for (HullView& view : views) views_.push_back(std::move(view));
  std::vector<DeferredUpdate> deferred;
  Refiner(cube_, views_, &deferred, kParallelDepth).updateRoot(*root_, first_new);
  const Refiner refiner(cube_, views_, nullptr, 0);
  detail::parallelFor(deferred.size(), config_.threads, [&](size_t i) {
    refiner.updateChildren(*deferred[i].node, deferred[i].cell, deferred[i].views);
  });
}

void VisualHull::addView(HullView view) {
  std::vector<HullView> one;
  one.push_back(std::move(view));
  addViews(std::move(one));
}

void VisualHull::dropLastView() {
  if (views_.empty()) return;
  std::vector<HullView> others = std::move(views_);
  others.pop_back();
  const std::vector<Eigen::Vector3i> free = freeVoxels();
  reset();
  addViews(std::move(others));
  carveFree(free);
}

bool VisualHull::isEmpty() const { return !holdsOccupied(*root_); }

void VisualHull::reset() {
  views_.clear();
  free_.clear();
  root_ = std::make_unique<OctreeNode>();
}

void VisualHull::forEachLeaf(const std::function<void(const HullCell&)>& visit) const {
  visitLeaves(*root_, CellIndex{}, visit);
}

HullStats VisualHull::stats() const {
  HullStats stats;
  const double voxel_m3 = std::pow(cube_.resolution_m, 3);
  forEachLeaf([&](const HullCell& cell) {
    const double cell_m3 = voxel_m3 * std::pow(8.0, cube_.depth - cell.depth);
    if (cell.state == CellState::kOut) ++stats.out_leaves;
    if (cell.state == CellState::kIn) ++stats.in_leaves, stats.occupied_volume_m3 += cell_m3;
    if (cell.state == CellState::kSurface) {
      ++stats.surface_leaves;
      if (cell.centre_value <= 0.0f) stats.occupied_volume_m3 += cell_m3;
    }
  });
  const size_t leaves = stats.in_leaves + stats.out_leaves + stats.surface_leaves;
  stats.nodes = leaves + (leaves - 1) / 7;
  stats.bytes = stats.nodes * sizeof(OctreeNode);
  return stats;
}

HullCell VisualHull::leafAt(const Eigen::Vector3d& X_W) const {
  const Eigen::Vector3d voxel = (X_W - cube_.origin_W()) / cube_.resolution_m;
  const int cells = 1 << cube_.depth;
  if (!((voxel.array() >= 0.0).all() && (voxel.array() < cells).all())) {
    return {Eigen::Vector3i::Zero(), 0, CellState::kOut, HullView::kFarOutside_px};
  }
  const Eigen::Vector3i finest = voxel.array().floor().cast<int>();
  const OctreeNode* node = root_.get();
  CellIndex cell;
  while (node->children) {
    const int shift = cube_.depth - cell.depth - 1;
    const int child = ((finest.x() >> shift) & 1) | (((finest.y() >> shift) & 1) << 1) |
                      (((finest.z() >> shift) & 1) << 2);
    node = &node->children[child];
    cell = childOf(cell, child);
  }
  return {cell.index, cell.depth, node->state, node->centre_value};
}

float VisualHull::valueAt(const Eigen::Vector3d& X_W) const {
  float value = -HullView::kFarOutside_px;
  for (const HullView& view : views_) value = std::max(value, view.valueAt(X_W));
  return value;
}

void VisualHull::sampleField(const std::vector<Eigen::Vector3d>& points_W,
                             std::vector<float>* values) const {
  values->resize(points_W.size());
  std::vector<float> x(points_W.size()), y(points_W.size()), z(points_W.size());
  for (size_t i = 0; i < points_W.size(); ++i) {
    const Eigen::Vector3d X_local = (points_W[i] - frame_origin_W_) / frame_scale_;
    x[i] = static_cast<float>(X_local.x());
    y[i] = static_cast<float>(X_local.y());
    z[i] = static_cast<float>(X_local.z());
  }
  // Tiles of kFieldTileVoxels finest voxels: in each, only the views that can hold the maximum.
  const double tile_edge = kFieldTileVoxels * cube_.resolution_m / frame_scale_;
  detail::sampleMaxField(views_, x, y, z, tile_edge, config_.threads, values->data());
}

SurfaceCells VisualHull::surfaceCells() const {
  SurfaceCells cells;
  cells.origin_W = cube_.origin_W();
  cells.cell_edge_m = cube_.resolution_m;
  cells.cells.reserve(countSurfaceLeaves(*root_));
  collectSurfaceLeaves(*root_, CellIndex{}, &cells.cells);
  return cells;
}

TriangleMesh VisualHull::mesh() const {
  return marchingCubes(surfaceCells(), [this](const std::vector<Eigen::Vector3d>& points,
                                              std::vector<float>* values) {
    sampleField(points, values);
    addFreeField(points, values);
  });
}

std::vector<VoxelBlock> occupiedBlocks(const VisualHull& hull) {
  std::vector<VoxelBlock> occupied, carved;
  leafBlocks(hull, &occupied, &carved);
  return occupied;
}

void leafBlocks(const VisualHull& hull, std::vector<VoxelBlock>* occupied,
                std::vector<VoxelBlock>* carved) {
  std::unordered_set<uint64_t> hollow;
  for (const Eigen::Vector3i& voxel : hull.hollowVoxels()) hollow.insert(detail::voxelKey(voxel));
  const HullCube& cube = hull.cube();
  hull.forEachLeaf([&](const HullCell& cell) {
    const int edge = 1 << (cube.depth - cell.depth);
    const bool out = cell.state == CellState::kOut ||
                     (edge == 1 && !hollow.empty() && hollow.count(detail::voxelKey(cell.index)));
    (out ? carved : occupied)->push_back({cube.origin_voxels + cell.index * edge, edge});
  });
}

}  // namespace sift_hull
