#pragma once

#include <stdexcept>
#include <string>

namespace sift_hull {

/// Where the hull node's ~save writes the octree and the mesh for the requested `path`.
struct SavePaths {
  std::string octree;  ///< OctoMap binary (.bt)
  std::string mesh;    ///< binary PLY
};

/// The files for `path`: PATH.bt and PATH.ply; a path ending in .bt or .ply keeps that extension
/// for its file and gives the other file the other extension ("x.bt": x.bt and x.ply). A relative
/// path is the node's working directory's (~/.ros under roslaunch). Throws std::invalid_argument
/// for an empty path, or one that names a directory ("dir/") or only an extension (".bt").
inline SavePaths savePaths(const std::string& path) {
  if (path.empty()) throw std::invalid_argument("the path is empty");
  std::string stem = path;
  for (const std::string extension : {".bt", ".ply"}) {
    const size_t size = extension.size();
    if (stem.size() >= size && stem.compare(stem.size() - size, size, extension) == 0) {
      stem.resize(stem.size() - size);
      break;
    }
  }
  const size_t slash = stem.find_last_of('/');
  const std::string name = slash == std::string::npos ? stem : stem.substr(slash + 1);
  if (name.empty()) {
    throw std::invalid_argument("'" + path + "' names no file (give a path such as /tmp/hull)");
  }
  return {stem + ".bt", stem + ".ply"};
}

}  // namespace sift_hull
