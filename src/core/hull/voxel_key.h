#pragma once

// A finest voxel of a hull's cube (indices 0 .. 2^depth - 1 on each axis) as one 64-bit key, for
// the hash sets of free-space carving (free_carving.cpp, refine/free_space.cpp).

#include <Eigen/Core>
#include <cstdint>

namespace sift_hull {
namespace detail {

constexpr int kVoxelKeyBits = 21;  ///< per axis: limits::kMaxHullDepth is below this
constexpr uint64_t kVoxelKeyMask = (uint64_t{1} << kVoxelKeyBits) - 1;

/// Whether a voxel lies in a cube of `cells` per axis (only those have keys).
inline bool inCube(const Eigen::Vector3i& v, int cells) {
  return (v.array() >= 0).all() && (v.array() < cells).all();
}

/// Requires inCube: negative indices would run into the other axes' bits.
inline uint64_t voxelKey(const Eigen::Vector3i& v) {
  return (static_cast<uint64_t>(v.x()) << (2 * kVoxelKeyBits)) |
         (static_cast<uint64_t>(v.y()) << kVoxelKeyBits) | static_cast<uint64_t>(v.z());
}

inline Eigen::Vector3i voxelOfKey(uint64_t key) {
  return {static_cast<int>(key >> (2 * kVoxelKeyBits)),
          static_cast<int>((key >> kVoxelKeyBits) & kVoxelKeyMask),
          static_cast<int>(key & kVoxelKeyMask)};
}

}  // namespace detail
}  // namespace sift_hull
