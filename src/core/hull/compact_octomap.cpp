// The hull's OctoMap as toOctomap builds and prunes it, written straight from the hull's octree:
// each OctoMap node's state over its voxels is read off the hull's cells, so that no OctoMap node
// is allocated. The hull's cube lies anywhere on the voxel grid, so an OctoMap node is covered by
// up to two hull cells of its size on each axis (its cover); the tree is walked once, the covers
// of a node's children taken from the children of its cover. The subtrees of a quarter of the
// cube's edge are written on the hull's threads and joined in OctoMap's order.

#include <cstdint>
#include <string>
#include <unordered_set>
#include <utility>
#include <vector>

#include "common/parallel.h"
#include "hull/octomap_keys.h"
#include "hull/octree_node.h"
#include "sift_hull/hull/hull_octomap.h"

namespace sift_hull {
namespace {

using detail::OctreeNode;
using namespace octomap_keys;

/// OctoMap's child codes in its binary stream.
enum : uint8_t { kUnknown = 0, kFree = 1, kOccupied = 2, kInner = 3 };

/// floor(value / 2^shift) for any sign.
inline int floorShift(int value, int shift) {
  return value >= 0 ? value >> shift : -((-value + (1 << shift) - 1) >> shift);
}

/// The hull cells of an OctoMap node's size that hold its voxels: slot x | y << 1 | z << 2 is the
/// cell at grid position first + (x, y, z) (in cells of that size from the cube's corner), or the
/// leaf above it; nullptr beyond the cube or where the node does not reach (a second cell on an
/// axis where the node lies on the grid).
struct Cover {
  const OctreeNode* slot[8];
};

/// The finest leaves of the voxels VisualHull::hollowVoxels lists (free in the maps).
std::unordered_set<const OctreeNode*> hollowLeaves(const VisualHull& hull) {
  std::unordered_set<const OctreeNode*> leaves;
  const int depth = hull.cube().depth;
  for (const Eigen::Vector3i& voxel : hull.hollowVoxels()) {
    const OctreeNode* node = &hull.rootNode();
    for (int level = 0; level < depth && node->children; ++level) {
      const int shift = depth - level - 1;
      node = &node->children[((voxel.x() >> shift) & 1) | (((voxel.y() >> shift) & 1) << 1) |
                             (((voxel.z() >> shift) & 1) << 2)];
    }
    leaves.insert(node);
  }
  return leaves;
}

/// The cube's depth from which its subtrees are written in parallel.
constexpr int kMinParallelDepth = 6;

class OctomapWriter {
 public:
  OctomapWriter(const VisualHull& hull, bool centres, CompactOctomap* map)
      : root_(&hull.rootNode()),
        depth_(hull.cube().depth),
        threads_(hull.config().threads),
        origin_key_(hull.cube().origin_voxels + Eigen::Vector3i::Constant(kKeyOffset)),
        centres_(centres),
        map_(map),
        hollow_(hollowLeaves(hull)) {
    toKeys({hull.cube().origin_voxels, 1 << depth_});  // throws beyond OctoMap's key range
    tabulateLevels();
  }

  /// OccupancyOcTreeBase::writeBinaryNode from OctoMap's root. In parallel: a first walk down to
  /// the split level lists its nodes (what it writes is thrown away), they are written on the
  /// threads, and a second walk, the same down to the split level, joins them in order.
  void write() {
    if (threads_ <= 1 || depth_ < kMinParallelDepth) {
      writeAbove(0, Eigen::Vector3i::Zero(), map_);
      return;
    }
    split_level_ = cubeLevel() + 2;
    CompactOctomap listing;
    stage_ = Stage::kList;
    writeAbove(0, Eigen::Vector3i::Zero(), &listing);
    stage_ = Stage::kSubtrees;
    parts_.resize(splits_.size());
    detail::parallelFor(splits_.size(), threads_, [&](size_t i) {
      parts_[i].code =
          writeCovered(split_level_, splits_[i].first, splits_[i].second, &parts_[i].map);
    });
    stage_ = Stage::kJoin;
    writeAbove(0, Eigen::Vector3i::Zero(), map_);
  }

 private:
  enum class Stage { kList, kSubtrees, kJoin };
  struct Part {
    uint8_t code = kUnknown;
    CompactOctomap map;
  };

  int cubeLevel() const { return kKeyDepth - depth_; }

  uint8_t leafCode(const OctreeNode& node) const {
    if (node.state == CellState::kOut) return kFree;
    return !hollow_.empty() && hollow_.count(&node) ? kFree : kOccupied;
  }

  /// A node of the split level while listing (none written) or joining (its written subtree).
  uint8_t split(const Eigen::Vector3i& min_key, const Cover& cover, CompactOctomap* out) {
    if (stage_ == Stage::kList) {
      splits_.emplace_back(min_key, cover);
      return kUnknown;
    }
    Part& part = parts_[joined_++];
    out->binary_data += part.map.binary_data;
    out->occupied_centres_W.insert(out->occupied_centres_W.end(),
                                   part.map.occupied_centres_W.begin(),
                                   part.map.occupied_centres_W.end());
    return part.code;
  }

  /// A node larger than the cube: unknown unless it holds some of it, then inner (it also holds
  /// voxels beyond the cube).
  uint8_t writeAbove(int level, const Eigen::Vector3i& min_key, CompactOctomap* out) {
    const int edge = 1 << (kKeyDepth - level);
    const Eigen::Vector3i first = min_key - origin_key_;
    const int cube_edge = 1 << depth_;
    if ((first.array() >= cube_edge).any() || (first.array() + edge <= 0).any()) return kUnknown;
    return writeInner(level, min_key, out, [&](const Eigen::Vector3i& child_key) {
      if (level + 1 < cubeLevel()) return writeAbove(level + 1, child_key, out);
      return writeCovered(level + 1, child_key, cubeCover(child_key), out);
    });
  }

  /// The cover of a node of the cube's size: the root in the slot at grid position 0.
  Cover cubeCover(const Eigen::Vector3i& min_key) const {
    Cover cover{};
    const Eigen::Vector3i first = min_key - origin_key_;
    int slot = 0;
    for (int a = 0; a < 3; ++a) {
      const int position = floorShift(first[a], depth_);
      if (position == -1 && first[a] % (1 << depth_) != 0) {
        slot |= 1 << a;
      } else if (position != 0) {
        return cover;
      }
    }
    cover.slot[slot] = root_;
    return cover;
  }

  /// A node within the cube's size: a leaf where its cover is, over the voxels it reaches, one
  /// state (or nothing: unknown); else written as OctoMap writes it, and a leaf after all when its
  /// eight children are leaves of one state (OctoMap's pruning).
  uint8_t writeCovered(int level, const Eigen::Vector3i& min_key, const Cover& cover,
                       CompactOctomap* out) {
    const unsigned int reach = reach_[level];
    bool unknown = false, mixed = false;
    uint8_t state = kUnknown;
    for (int s = 0; s < 8; ++s) {
      if (!(reach >> s & 1u)) continue;
      const OctreeNode* node = cover.slot[s];
      if (!node) {
        unknown = true;
      } else if (node->children) {
        mixed = true;
      } else {
        const uint8_t code = leafCode(*node);
        if (state != kUnknown && state != code) mixed = true;
        state = code;
      }
    }
    if (state == kUnknown && !mixed) return kUnknown;  // beyond the cube
    if (!unknown && !mixed) return state;
    unsigned int c = 0;
    return writeInner(level, min_key, out, [&](const Eigen::Vector3i& child_key) {
      Cover child;
      const int8_t* from = child_slots_[level][c++];
      for (int s = 0; s < 8; ++s) {
        const OctreeNode* parent = from[s] < 0 ? nullptr : cover.slot[from[s] >> 3];
        child.slot[s] = !parent            ? nullptr
                        : parent->children ? &parent->children[from[s] & 7]
                                           : parent;
      }
      if (level + 1 == split_level_ && stage_ != Stage::kSubtrees) {
        return split(child_key, child, out);
      }
      return writeCovered(level + 1, child_key, child, out);
    });
  }

  /// The slots a node at each level reaches, and where the slots of its children come from:
  /// nodes of one level all lie alike on the grid of hull cells of their size (their first keys
  /// are multiples of their edge), at an offset `within` (per axis, voxels) from the cube's grid.
  void tabulateLevels() {
    for (int level = cubeLevel(); level <= kKeyDepth; ++level) {
      const int edge = 1 << (kKeyDepth - level);
      int within[3];
      unsigned int reach = 0xFFu;
      for (int a = 0; a < 3; ++a) {
        within[a] = (((-origin_key_[a]) % edge) + edge) % edge;
        if (within[a] == 0) {
          for (int s = 0; s < 8; ++s) {
            if (s >> a & 1) reach &= ~(1u << s);
          }
        }
      }
      reach_[level] = reach;
      if (level == kKeyDepth) break;
      const int half = edge / 2;
      for (unsigned int c = 0; c < 8; ++c) {
        for (int s = 0; s < 8; ++s) {
          int parent_slot = 0, child_index = 0;
          bool reached = true;
          for (int a = 0; a < 3; ++a) {
            const int child_within = within[a] + static_cast<int>(c >> a & 1u) * half;
            if ((s >> a & 1) && child_within % half == 0) reached = false;
            const int cell = child_within / half + (s >> a & 1);  // in cells of `half` from the
            parent_slot |= (cell >> 1) << a;                      // node's first cell of `edge`
            child_index |= (cell & 1) << a;
          }
          child_slots_[level][c][s] =
              reached ? static_cast<int8_t>(parent_slot << 3 | child_index) : int8_t{-1};
        }
      }
    }
  }

  /// Writes a node's two bytes and, after them, its inner children (childCode(key) writes the
  /// next child, in OctoMap's order, and gives its code); the centres of its occupied children.
  /// kInner, or the code of its eight children when they are leaves of one known state (nothing
  /// written then).
  template <typename ChildCode>
  uint8_t writeInner(int level, const Eigen::Vector3i& min_key, CompactOctomap* out,
                     ChildCode childCode) {
    const int edge = 1 << (kKeyDepth - level);
    const size_t start = out->binary_data.size();
    out->binary_data.append(2, '\0');
    uint8_t codes[8];
    uint8_t halves[2] = {0, 0};
    for (unsigned int c = 0; c < 8; ++c) {
      codes[c] = childCode(childKey(min_key, edge, c));
      // kInner sets bits 2c and 2c + 1, kOccupied bit 2c + 1, kFree bit 2c (writeBinaryNode).
      const unsigned int bits = codes[c] == kInner ? 3u : codes[c] == kOccupied ? 2u : codes[c];
      halves[c / 4] |= static_cast<uint8_t>(bits << (2 * (c % 4)));
    }
    bool uniform = level > 0 && (codes[0] == kFree || codes[0] == kOccupied);
    for (unsigned int c = 1; c < 8 && uniform; ++c) uniform = codes[c] == codes[0];
    if (uniform) {
      out->binary_data.resize(start);
      return codes[0];
    }
    out->binary_data[start] = static_cast<char>(halves[0]);
    out->binary_data[start + 1] = static_cast<char>(halves[1]);
    for (unsigned int c = 0; c < 8 && centres_; ++c) {
      if (codes[c] == kOccupied) addCentre(level + 1, childKey(min_key, edge, c), out);
    }
    return kInner;
  }

  /// OcTreeBaseImpl::keyToCoord of an occupied leaf's key at its depth.
  void addCentre(int level, const Eigen::Vector3i& min_key, CompactOctomap* out) const {
    const int edge = 1 << (kKeyDepth - level);
    const double resolution_m = map_->resolution_m;
    const Eigen::Vector3d offset = (min_key.array() - kKeyOffset).cast<double>();
    Eigen::Vector3d centre;
    if (edge == 1) {
      centre = (offset.array() + 0.5) * resolution_m;
    } else {
      centre = (offset.array() / edge + 0.5) * (resolution_m * edge);
    }
    out->occupied_centres_W.push_back(centre);
  }

  const OctreeNode* root_;
  const int depth_;
  const int threads_;
  const Eigen::Vector3i origin_key_;  ///< the key of the cube's first voxel
  const bool centres_;                ///< whether the occupied leaves' centres are wanted
  CompactOctomap* map_;
  const std::unordered_set<const OctreeNode*> hollow_;
  Stage stage_ = Stage::kJoin;
  int split_level_ = -1;  ///< none: written in one walk
  std::vector<std::pair<Eigen::Vector3i, Cover>> splits_;
  std::vector<Part> parts_;
  size_t joined_ = 0;
  unsigned int reach_[kKeyDepth + 1] = {};
  int8_t child_slots_[kKeyDepth][8][8] = {};
};

}  // namespace

CompactOctomap compactOctomap(const VisualHull& hull, bool occupied_centres) {
  CompactOctomap map;
  map.resolution_m = hull.cube().resolution_m;
  OctomapWriter(hull, occupied_centres, &map).write();
  return map;
}

}  // namespace sift_hull
