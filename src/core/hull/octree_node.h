#pragma once

// The octree's node, for the files that walk VisualHull's tree (octree.cpp, compact_octomap.cpp).

#include <memory>

#include "sift_hull/hull/octree.h"

namespace sift_hull {
namespace detail {

struct OctreeNode {
  CellState state = CellState::kIn;
  float centre_value = -HullView::kFarOutside_px;
  std::unique_ptr<OctreeNode[]> children;  ///< eight, or none for a leaf
};

}  // namespace detail
}  // namespace sift_hull
