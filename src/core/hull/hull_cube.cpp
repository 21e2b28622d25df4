#include <cmath>
#include <sstream>
#include <stdexcept>

#include "sift_hull/hull/octree.h"
#include "sift_hull/limits.h"

namespace sift_hull {
namespace {

double longestEdge(const Box3d& box) {
  const double longest_m = box.size().maxCoeff();
  if (!(longest_m > 0.0) || !std::isfinite(longest_m)) {
    throw std::invalid_argument("hull box must have a positive, finite size");
  }
  return longest_m;
}

/// The cube of 2^depth cells of `resolution_m` whose corner, on the voxel grid, lies at least one
/// cell below the box's on every axis.
HullCube cubeAt(const Box3d& box, int depth, double resolution_m) {
  HullCube cube;
  cube.depth = depth;
  cube.resolution_m = resolution_m;
  const Eigen::Vector3d corner = box.min_W / cube.resolution_m - Eigen::Vector3d::Ones();
  // Voxel indices of the cube's cells must fit an int (and its far corner too).
  constexpr double kMaxVoxelIndex = 1 << 30;
  if (!(corner.cwiseAbs().maxCoeff() < kMaxVoxelIndex) || !box.min_W.allFinite()) {
    throw std::invalid_argument(
        "the hull box lies more than 2^30 voxels from the world origin at this resolution: "
        "express the poses in a frame nearer the object, or lower the depth");
  }
  cube.origin_voxels = corner.array().floor().cast<int>();
  return cube;
}

}  // namespace

HullCube HullCube::around(const Box3d& box, int depth) {
  // 2^depth voxels = longest edge + 3: snapping the corner down costs up to one voxel, and at
  // least one voxel of margin remains on every side.
  return cubeAt(box, depth, longestEdge(box) / ((1 << depth) - 3));
}

HullCube HullCube::withResolution(const Box3d& box, double resolution_m) {
  const double longest_m = longestEdge(box);
  if (!(resolution_m > 0.0) || !std::isfinite(resolution_m)) {
    throw std::invalid_argument("the hull's resolution_m must be positive and finite");
  }
  for (int depth = 2; depth <= limits::kMaxHullDepth; ++depth) {
    if (resolution_m * ((1 << depth) - 3) < longest_m) continue;
    const HullCube cube = cubeAt(box, depth, resolution_m);
    if (!std::isfinite(cube.edge_m()) || !cube.origin_W().allFinite()) {
      std::ostringstream why;
      why << "resolution_m " << resolution_m << " m is too large: the octree's cube of "
          << (1 << depth) << " cells would have no finite edge";
      throw std::invalid_argument(why.str());
    }
    return cube;
  }
  std::ostringstream why;
  why << "resolution_m " << resolution_m << " m needs an octree deeper than "
      << limits::kMaxHullDepth << " levels for a box whose longest edge is " << longest_m
      << " m: raise resolution_m (at least " << longest_m / ((1 << limits::kMaxHullDepth) - 3)
      << " m) or give a smaller box";
  throw std::invalid_argument(why.str());
}

HullCube HullCube::forConfig(const Box3d& box, const HullConfig& config) {
  return config.resolution_m > 0.0 ? withResolution(box, config.resolution_m)
                                   : around(box, config.max_depth);
}

Box3d HullCube::box() const {
  Box3d result;
  result.min_W = origin_W();
  result.max_W = result.min_W + Eigen::Vector3d::Constant(edge_m());
  return result;
}

}  // namespace sift_hull
