#pragma once

#include <iosfwd>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "sift_hull/hull/bounding_box.h"
#include "sift_hull/hull/octree.h"

namespace octomap {
class OcTree;
}

namespace sift_hull {

/// The hull as an OctoMap at the hull's resolution, pruned: in cells and finest surface cells
/// occupied (log-odds at the clamping maximum), carved (out) cells free (log-odds at the clamping
/// minimum) at their own octree level, so the whole cube is known and only space outside it is
/// unknown. The hull's voxels line up with the OctoMap's (HullCube). Throws std::out_of_range
/// when the cube lies beyond the OctoMap's 2^16-voxel key range around the world origin.
std::unique_ptr<octomap::OcTree> toOctomap(const VisualHull& hull);

/// toOctomap's map without OctoMap's nodes, for what is published per view: the same pruned tree
/// built in an array of its own (several times faster). `binary_data` equals
/// writeOctomapBinaryData(*toOctomap(hull)) byte for byte; `occupied_centres_W` are that tree's
/// occupied leaves' centres (any order), left empty unless `occupied_centres`. Throws as
/// toOctomap.
struct CompactOctomap {
  double resolution_m = 0.0;
  std::string binary_data;
  std::vector<Eigen::Vector3d> occupied_centres_W;
};
CompactOctomap compactOctomap(const VisualHull& hull, bool occupied_centres = true);

/// Whether a box (metres) can be cleared: finite, min <= max on each axis.
bool isValidClearBox(const Box3d& box_W);

/// Sets every known voxel the box touches free (log-odds at the clamping minimum), as
/// octomap_server's ~clear_bbx does, but to the voxel: a coarser leaf the box cuts is split, so
/// only its part in the box changes. Unknown space stays unknown. The tree is pruned again.
/// Throws std::invalid_argument for a box that is not isValidClearBox.
void clearBox(const Box3d& box_W, octomap::OcTree* tree);

/// Writes OctoMap's binary .bt file (the header OcTree::writeBinary writes, then the binary data).
/// With a `carving_box`, the box the hull was carved in (metres, the tree's frame) is a line of the
/// header, `# carving_box XMIN,YMIN,ZMIN,XMAX,YMAX,ZMAX`, exact to the double: a comment to
/// OctoMap's readers (octovis, octomap_server), the box to readCarvingBox and `sift_hull hull --box
/// FILE`. Throws std::runtime_error naming the path on failure.
void writeOctomap(const octomap::OcTree& tree, const std::string& path,
                  const std::optional<Box3d>& carving_box = std::nullopt);

/// A box as `sift_hull hull --box` takes it: XMIN,YMIN,ZMIN,XMAX,YMAX,ZMAX, exact to the double.
std::string boxText(const Box3d& box_W);

/// The carving box in the header of an OctoMap file writeOctomap wrote; nullopt when the header has
/// none. Throws std::runtime_error naming the path for a file that cannot be read, is not an
/// OctoMap file, or whose carving_box line is not six finite numbers with min <= max.
std::optional<Box3d> readCarvingBox(const std::string& path);

/// OctoMap's binary stream of the tree (OcTree::writeBinaryData's bytes, as octomap_msgs'
/// binaryMapToMsg puts them into a message) without the progress lines the library prints on
/// stderr.
void writeOctomapBinaryData(const octomap::OcTree& tree, std::ostream& out);

}  // namespace sift_hull
