#pragma once

#include <octomap/OcTree.h>

#include <cmath>
#include <sstream>
#include <string>

#include "sift_hull/Octomap.h"

namespace sift_hull {
namespace test {

/// The occupied volume of an Octomap message (cubic metres), 0 for an empty tree.
inline double occupiedVolume(const sift_hull::Octomap& message) {
  if (message.data.empty()) return 0.0;  // an empty tree
  octomap::OcTree tree(message.resolution);
  std::stringstream data(std::string(message.data.begin(), message.data.end()));
  tree.readBinaryData(data);
  double volume = 0.0;
  for (auto leaf = tree.begin_leafs(); leaf != tree.end_leafs(); ++leaf) {
    if (tree.isNodeOccupied(*leaf)) volume += std::pow(leaf.getSize(), 3);
  }
  return volume;
}

}  // namespace test
}  // namespace sift_hull
