#pragma once

#include <string>

#include "sift_hull/hull/mesh.h"

namespace sift_hull {

/// Binary little-endian PLY: float x y z per vertex (then uchar red green blue when the mesh has
/// colours), uchar-counted int list per face. Throws std::runtime_error naming the path when it
/// cannot be written / read or is not such a file, and when writing a mesh whose colours are not
/// one per vertex.
void writePly(const std::string& path, const TriangleMesh& mesh);
TriangleMesh readPly(const std::string& path);

}  // namespace sift_hull
