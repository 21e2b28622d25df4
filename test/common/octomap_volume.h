#pragma once

#include <octomap/OcTree.h>

#include <cmath>
#include <memory>
#include <sstream>
#include <string>

#include "sift_hull/Octomap.h"

namespace sift_hull {
namespace test {

/// The occupied volume of a tree (cubic metres).
inline double occupiedVolume(const octomap::OcTree& tree) {
  double volume = 0.0;
  for (auto leaf = tree.begin_leafs(); leaf != tree.end_leafs(); ++leaf) {
    if (tree.isNodeOccupied(*leaf)) volume += std::pow(leaf.getSize(), 3);
  }
  return volume;
}

/// The tree of a binary Octomap message (empty for an empty message).
inline std::unique_ptr<octomap::OcTree> binaryTree(const sift_hull::Octomap& message) {
  auto tree = std::make_unique<octomap::OcTree>(message.resolution > 0 ? message.resolution : 0.1);
  if (message.data.empty()) return tree;
  std::stringstream data(std::string(message.data.begin(), message.data.end()));
  tree->readBinaryData(data);
  return tree;
}

/// The occupied volume of an Octomap message (cubic metres), 0 for an empty tree.
inline double occupiedVolume(const sift_hull::Octomap& message) {
  if (message.data.empty()) return 0.0;  // an empty tree
  return occupiedVolume(*binaryTree(message));
}

}  // namespace test
}  // namespace sift_hull
