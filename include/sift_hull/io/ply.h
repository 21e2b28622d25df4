#pragma once

#include <string>

#include "sift_hull/hull/mesh.h"

namespace sift_hull {

/// Binary little-endian PLY: float x y z per vertex, uchar-counted int list per face. Throws
/// std::runtime_error naming the path when it cannot be written / read or is not such a file.
void writePly(const std::string& path, const TriangleMesh& mesh);
TriangleMesh readPly(const std::string& path);

}  // namespace sift_hull
