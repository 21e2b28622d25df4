#pragma once

#include <sys/stat.h>
#include <unistd.h>

#include <cerrno>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <functional>
#include <stdexcept>
#include <string>
#include <vector>

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

/// Throws std::invalid_argument when `path` holds a NUL byte, or names something that exists and
/// is not a regular file (a FIFO, a directory, a device): ~save writes only regular files, and
/// opening a FIFO would wait for a reader.
inline void checkRegularTarget(const std::string& path) {
  if (path.find('\0') != std::string::npos) {
    throw std::invalid_argument("the path holds a NUL byte");
  }
  struct stat info;
  if (::stat(path.c_str(), &info) == 0 && !S_ISREG(info.st_mode)) {
    throw std::invalid_argument("'" + path + "' exists and is not a regular file");
  }
}

/// Writes `path` through a new temporary file beside it (created exclusively, so never a FIFO or
/// someone else's file), renamed over `path` once `write(temporary)` has written it: a reader
/// sees the old file or the whole new one. The temporary is removed when anything fails, and the
/// error rethrown; a failure to create it throws std::runtime_error naming `path`.
inline void writeReplacing(const std::string& path,
                           const std::function<void(const std::string&)>& write) {
  checkRegularTarget(path);
  std::vector<char> name(path.begin(), path.end());
  for (char c : std::string(".tmp-XXXXXX")) name.push_back(c);
  name.push_back('\0');
  const int fd = ::mkstemp(name.data());
  if (fd < 0) throw std::runtime_error(path + ": cannot write beside it: " + std::strerror(errno));
  ::fchmod(fd, 0644);  // as an ordinary file would be, not mkstemp's 0600
  ::close(fd);
  const std::string temporary(name.data());
  try {
    write(temporary);
    if (std::rename(temporary.c_str(), path.c_str()) != 0) {
      throw std::runtime_error(path + ": cannot replace: " + std::strerror(errno));
    }
  } catch (...) {
    std::remove(temporary.c_str());
    throw;
  }
}

}  // namespace sift_hull
