#pragma once

#include <iosfwd>
#include <memory>
#include <string>

#include "sift_hull/hull/octree.h"

namespace octomap {
class OcTree;
}

namespace sift_hull {

/// The hull as an OctoMap at the hull's resolution: in cells and finest surface cells occupied
/// (log-odds at the clamping maximum), everything else unknown, pruned. The hull's voxels line up
/// with the OctoMap's (HullCube). Throws std::out_of_range when the cube lies beyond the OctoMap's
/// 2^16-voxel key range around the world origin.
std::unique_ptr<octomap::OcTree> toOctomap(const VisualHull& hull);

/// Writes OctoMap's binary .bt file (the header OcTree::writeBinary writes, then the binary data).
/// Throws std::runtime_error naming the path on failure.
void writeOctomap(const octomap::OcTree& tree, const std::string& path);

/// OctoMap's binary stream of the tree (OcTree::writeBinaryData's bytes, as octomap_msgs'
/// binaryMapToMsg puts them into a message) without the progress lines the library prints on
/// stderr.
void writeOctomapBinaryData(const octomap::OcTree& tree, std::ostream& out);

}  // namespace sift_hull
