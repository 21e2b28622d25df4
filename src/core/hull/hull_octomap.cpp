#include "sift_hull/hull/hull_octomap.h"

#include <octomap/OcTree.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <fstream>
#include <iomanip>
#include <limits>
#include <ostream>
#include <sstream>
#include <stdexcept>
#include <string>

#include "hull/octomap_keys.h"

namespace sift_hull {
namespace {

using namespace octomap_keys;

/// The node becomes a leaf of the given log-odds.
void makeLeaf(octomap::OcTree* tree, octomap::OcTreeNode* node, float log_odds) {
  for (unsigned int c = 0; c < 8; ++c) {
    if (tree->nodeChildExists(node, c)) tree->deleteNodeChild(node, c);
  }
  node->setLogOdds(log_odds);
}

/// An OcTree that takes whole blocks of voxels, setting the largest aligned nodes inside a block
/// at once instead of every voxel.
class BlockOcTree : public octomap::OcTree {
 public:
  using octomap::OcTree::OcTree;

  /// A cubic block (the hull's cells) whose voxels all take `log_odds`.
  void insertBlock(const KeyBox& block, float log_odds) {
    if (root == nullptr) {
      root = new octomap::OcTreeNode();
      ++tree_size;
    }
    if (isAligned(block)) return insertAligned(block, log_odds);
    insert(root, 0, Eigen::Vector3i::Zero(), block, log_odds);
  }

 private:
  static bool isAligned(const KeyBox& block) {
    const int edge = block.end_key.x() - block.min_key.x();
    const Eigen::Vector3i& key = block.min_key;
    return key.x() % edge == 0 && key.y() % edge == 0 && key.z() % edge == 0;
  }

  /// A block that is one octree node (most of them: the hull's cells are octree cells): the path
  /// to it is read off its key bits, with no overlap tests.
  void insertAligned(const KeyBox& block, float log_odds) {
    const int edge = block.end_key.x() - block.min_key.x();
    octomap::OcTreeNode* node = root;
    for (int level = 0; (1 << (kKeyDepth - level)) > edge; ++level) {
      const int bit = kKeyDepth - 1 - level;
      const unsigned int c = ((block.min_key.x() >> bit) & 1) |
                             (((block.min_key.y() >> bit) & 1) << 1) |
                             (((block.min_key.z() >> bit) & 1) << 2);
      node = nodeChildExists(node, c) ? getNodeChild(node, c) : createNodeChild(node, c);
    }
    makeLeaf(this, node, log_odds);
  }

  void insert(octomap::OcTreeNode* node, int level, const Eigen::Vector3i& min_key,
              const KeyBox& block, float log_odds) {
    const int edge = 1 << (kKeyDepth - level);
    if (within(min_key, edge, block)) return makeLeaf(this, node, log_odds);
    for (unsigned int c = 0; c < 8; ++c) {
      const Eigen::Vector3i child_key = childKey(min_key, edge, c);
      if (!overlaps(child_key, edge / 2, block)) continue;
      octomap::OcTreeNode* child =
          nodeChildExists(node, c) ? getNodeChild(node, c) : createNodeChild(node, c);
      insert(child, level + 1, child_key, block, log_odds);
    }
  }
};

/// Sets the known voxels of `box` below `node` (at `level`, its first key `min_key`) free,
/// splitting leaves that the box cuts (prune merges them again).
void clearNode(octomap::OcTree* tree, octomap::OcTreeNode* node, int level,
               const Eigen::Vector3i& min_key, const KeyBox& box) {
  const int edge = 1 << (kKeyDepth - level);
  const bool inside = within(min_key, edge, box);
  if (!tree->nodeHasChildren(node)) {
    if (inside) return node->setLogOdds(tree->getClampingThresMinLog());
    tree->expandNode(node);
  }
  // A node with children has unknown space where a child is missing: only its children change.
  for (unsigned int c = 0; c < 8; ++c) {
    const Eigen::Vector3i child_key = childKey(min_key, edge, c);
    if (!tree->nodeChildExists(node, c) || !overlaps(child_key, edge / 2, box)) continue;
    clearNode(tree, tree->getNodeChild(node, c), level + 1, child_key, box);
  }
}

/// Prunes bottom up through every level: OcTree::prune stops at the first level where nothing
/// collapsed, which can leave a coarser collapsible node (the hull's blocks come in at their own
/// levels), so that the tree would not be the canonical one compactOctomap writes.
void pruneFully(octomap::OcTree* tree, octomap::OcTreeNode* node, bool is_root) {
  if (!tree->nodeHasChildren(node)) return;
  for (unsigned int c = 0; c < 8; ++c) {
    if (tree->nodeChildExists(node, c)) pruneFully(tree, tree->getNodeChild(node, c), false);
  }
  if (!is_root && tree->isNodeCollapsible(node)) tree->pruneNode(node);
}

void pruneFully(octomap::OcTree* tree) {
  if (tree->getRoot() != nullptr) pruneFully(tree, tree->getRoot(), true);
}

/// The keys of the voxels a metric box touches, clipped to OctoMap's key range.
KeyBox touchedKeys(const octomap::OcTree& tree, const Box3d& box_W) {
  const auto key = [&](double coordinate_m) {
    const double k = std::floor(coordinate_m / tree.getResolution()) + kKeyOffset;
    return static_cast<int>(std::clamp(k, -1.0, 2.0 * kKeyOffset));
  };
  KeyBox keys;
  for (int axis = 0; axis < 3; ++axis) {
    keys.min_key[axis] = std::max(key(box_W.min_W[axis]), 0);
    keys.end_key[axis] = std::min(key(box_W.max_W[axis]) + 1, 2 * kKeyOffset);
  }
  return keys;
}

}  // namespace

std::unique_ptr<octomap::OcTree> toOctomap(const VisualHull& hull) {
  auto tree = std::make_unique<BlockOcTree>(hull.cube().resolution_m);
  const float occupied = tree->getClampingThresMaxLog(), free = tree->getClampingThresMinLog();
  std::vector<VoxelBlock> occupied_blocks, carved_blocks;
  leafBlocks(hull, &occupied_blocks, &carved_blocks);
  for (const VoxelBlock& block : occupied_blocks) tree->insertBlock(toKeys(block), occupied);
  for (const VoxelBlock& block : carved_blocks) tree->insertBlock(toKeys(block), free);
  tree->updateInnerOccupancy();
  pruneFully(tree.get());
  return tree;
}

namespace {

/// OccupancyOcTreeBase::writeBinaryNode's bytes, appended to `bytes`: per inner node two bytes of
/// two bits per child (00 unknown, 01 occupied, 10 free, 11 inner; bit 2i and 2i + 1 for child i
/// of the first and of the second four), then its inner children in order. One buffer instead of
/// two stream writes per node.
void appendBinaryNode(const octomap::OcTree& tree, const octomap::OcTreeNode* node,
                      std::string* bytes) {
  uint8_t halves[2] = {0, 0};
  for (unsigned int i = 0; i < 8; ++i) {
    if (!tree.nodeChildExists(node, i)) continue;
    const octomap::OcTreeNode* child = tree.getNodeChild(node, i);
    const unsigned int code =
        tree.nodeHasChildren(child) ? 3u : (tree.isNodeOccupied(child) ? 2u : 1u);
    // 3 sets bits 2i and 2i + 1 (inner), 2 bit 2i + 1 (occupied), 1 bit 2i (free).
    halves[i / 4] |= static_cast<uint8_t>(code << (2 * (i % 4)));
  }
  bytes->push_back(static_cast<char>(halves[0]));
  bytes->push_back(static_cast<char>(halves[1]));
  for (unsigned int i = 0; i < 8; ++i) {
    if (!tree.nodeChildExists(node, i)) continue;
    const octomap::OcTreeNode* child = tree.getNodeChild(node, i);
    if (tree.nodeHasChildren(child)) appendBinaryNode(tree, child, bytes);
  }
}

}  // namespace

void writeOctomapBinaryData(const octomap::OcTree& tree, std::ostream& out) {
  if (tree.getRoot() == nullptr) return;
  std::string bytes;
  bytes.reserve(2 * tree.size());
  appendBinaryNode(tree, tree.getRoot(), &bytes);
  out.write(bytes.data(), static_cast<std::streamsize>(bytes.size()));
}

bool isValidClearBox(const Box3d& box_W) {
  return box_W.min_W.allFinite() && box_W.max_W.allFinite() &&
         (box_W.min_W.array() <= box_W.max_W.array()).all();
}

void clearBox(const Box3d& box_W, octomap::OcTree* tree) {
  if (!isValidClearBox(box_W)) {
    throw std::invalid_argument("the box to clear must be finite with min <= max on each axis");
  }
  const KeyBox keys = touchedKeys(*tree, box_W);
  if (tree->getRoot() == nullptr || !(keys.min_key.array() < keys.end_key.array()).all()) return;
  clearNode(tree, tree->getRoot(), 0, Eigen::Vector3i::Zero(), keys);
  tree->updateInnerOccupancy();
  pruneFully(tree);
}

namespace {

constexpr char kBinaryFileHeader[] = "# Octomap OcTree binary file";
constexpr char kCarvingBoxKey[] = "# carving_box ";

}  // namespace

void writeOctomap(const octomap::OcTree& tree, const std::string& path,
                  const std::optional<Box3d>& carving_box) {
  std::ofstream out(path, std::ios::binary);
  // AbstractOccupancyOcTree::writeBinaryConst's header; the first line is what readers check.
  out << kBinaryFileHeader << "\n"
      << "# (feel free to add / change comments, but leave the first line as it is!)\n#\n";
  if (carving_box) out << kCarvingBoxKey << boxText(*carving_box) << "\n";
  out << "id " << tree.getTreeType() << "\nsize " << tree.size() << "\nres " << tree.getResolution()
      << "\ndata\n";
  writeOctomapBinaryData(tree, out);
  out.close();
  if (!out) throw std::runtime_error(path + ": cannot write the octree");
}

std::string boxText(const Box3d& box_W) {
  std::ostringstream text;
  text << std::setprecision(std::numeric_limits<double>::max_digits10);
  for (int i = 0; i < 6; ++i)
    text << (i > 0 ? "," : "") << (i < 3 ? box_W.min_W[i] : box_W.max_W[i - 3]);
  return text.str();
}

std::optional<Box3d> readCarvingBox(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  std::string line;
  if (!in || !std::getline(in, line)) throw std::runtime_error(path + ": cannot read the file");
  if (line.compare(0, sizeof kBinaryFileHeader - 1, kBinaryFileHeader) != 0 &&
      line.compare(0, 22, "# Octomap OcTree file") != 0) {
    throw std::runtime_error(path + ": not an OctoMap file (its first line is not \"" +
                             kBinaryFileHeader + "\")");
  }
  // The header ends at "data"; OctoMap's own lines are at most a few words.
  for (int number = 2; number < 1000 && std::getline(in, line) && line != "data"; ++number) {
    if (line.compare(0, sizeof kCarvingBoxKey - 1, kCarvingBoxKey) != 0) continue;
    std::istringstream values(line.substr(sizeof kCarvingBoxKey - 1));
    std::array<double, 6> v{};
    char comma = ',';
    bool ok = true;
    for (size_t i = 0; i < v.size() && ok; ++i) {
      ok = (i == 0 || ((values >> comma) && comma == ',')) && (values >> v[i]) &&
           std::isfinite(v[i]);
    }
    Box3d box;
    box.min_W = Eigen::Vector3d(v[0], v[1], v[2]);
    box.max_W = Eigen::Vector3d(v[3], v[4], v[5]);
    values >> std::ws;
    if (!ok || !values.eof() || !(box.min_W.array() <= box.max_W.array()).all()) {
      throw std::runtime_error(path + ":" + std::to_string(number) +
                               ": the carving_box line must be six finite comma-separated numbers "
                               "XMIN,YMIN,ZMIN,XMAX,YMAX,ZMAX with min <= max");
    }
    return box;
  }
  return std::nullopt;
}

}  // namespace sift_hull
