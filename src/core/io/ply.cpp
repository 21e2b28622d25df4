#include "sift_hull/io/ply.h"

#include <Eigen/Geometry>
#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <fstream>
#include <iterator>
#include <limits>
#include <numeric>
#include <sstream>
#include <stdexcept>
#include <string>

namespace sift_hull {
namespace {

// ---------------------------------------------------------------------------------------------
// PLY

const char* const kPlyVertexHeader = "element vertex ";
const char* const kPlyFaceHeader = "element face ";
const std::array<const char*, 3> kPlyVertexProperties = {"property float x", "property float y",
                                                         "property float z"};
const std::array<const char*, 3> kPlyColourProperties = {
    "property uchar red", "property uchar green", "property uchar blue"};
constexpr size_t kPlyVertexBytes = 3 * 4;
constexpr size_t kPlyColourBytes = 3;
constexpr size_t kPlyFaceBytes = 1 + 3 * 4;

void appendLittleEndian(uint32_t value, std::string* bytes) {
  for (int shift = 0; shift < 32; shift += 8) {
    bytes->push_back(static_cast<char>((value >> shift) & 0xffu));
  }
}

uint32_t readLittleEndian(const char* bytes) {
  uint32_t value = 0;
  for (int i = 3; i >= 0; --i) value = (value << 8) | static_cast<unsigned char>(bytes[i]);
  return value;
}

uint32_t floatBits(float value) {
  uint32_t bits;
  std::memcpy(&bits, &value, sizeof bits);
  return bits;
}

float bitsToFloat(uint32_t bits) {
  float value;
  std::memcpy(&value, &bits, sizeof value);
  return value;
}

std::string plyHeader(const TriangleMesh& mesh) {
  std::string header = "ply\nformat binary_little_endian 1.0\n";
  header += kPlyVertexHeader + std::to_string(mesh.vertices_W.size()) + "\n";
  for (const char* property : kPlyVertexProperties) header += std::string(property) + "\n";
  if (!mesh.colours_rgb.empty()) {
    for (const char* property : kPlyColourProperties) header += std::string(property) + "\n";
  }
  header += kPlyFaceHeader + std::to_string(mesh.faces.size()) + "\n";
  header += "property list uchar int vertex_indices\nend_header\n";
  return header;
}

std::string plyBody(const TriangleMesh& mesh) {
  std::string body;
  body.reserve(mesh.vertices_W.size() * kPlyVertexBytes + mesh.faces.size() * kPlyFaceBytes);
  for (size_t v = 0; v < mesh.vertices_W.size(); ++v) {
    for (int axis = 0; axis < 3; ++axis) {
      appendLittleEndian(floatBits(mesh.vertices_W[v][axis]), &body);
    }
    if (mesh.colours_rgb.empty()) continue;
    for (const uint8_t channel : mesh.colours_rgb[v]) body.push_back(static_cast<char>(channel));
  }
  for (const Eigen::Vector3i& face : mesh.faces) {
    body.push_back(3);
    for (int k = 0; k < 3; ++k) appendLittleEndian(static_cast<uint32_t>(face[k]), &body);
  }
  return body;
}

[[noreturn]] void throwPlyError(const std::string& path, const std::string& what) {
  throw std::runtime_error(path + ": " + what);
}

struct PlyCounts {
  size_t vertices = 0;
  size_t faces = 0;
  bool colours = false;  ///< red, green, blue after each vertex's coordinates
};

// Reads a header line, skipping comments; false at the end of the stream.
bool nextHeaderLine(std::istream& in, std::string* line) {
  while (std::getline(in, *line)) {
    if (line->rfind("comment", 0) != 0) return true;
  }
  return false;
}

void expectLine(std::istream& in, const std::string& expected, const std::string& path) {
  std::string line;
  if (!nextHeaderLine(in, &line) || line != expected) {
    throwPlyError(path, "expected PLY header line '" + expected + "'");
  }
}

size_t expectCount(std::istream& in, const std::string& prefix, const std::string& path) {
  std::string line;
  const bool found = nextHeaderLine(in, &line) && line.rfind(prefix, 0) == 0;
  const std::string digits = found ? line.substr(prefix.size()) : std::string();
  const bool is_number =
      !digits.empty() && digits.size() <= 18 &&
      std::all_of(digits.begin(), digits.end(), [](char c) { return c >= '0' && c <= '9'; });
  if (!is_number) throwPlyError(path, "expected PLY header line '" + prefix + "<count>'");
  return static_cast<size_t>(std::stoull(digits));
}

PlyCounts readPlyHeader(std::istream& in, const std::string& path) {
  expectLine(in, "ply", path);
  expectLine(in, "format binary_little_endian 1.0", path);
  PlyCounts counts;
  counts.vertices = expectCount(in, kPlyVertexHeader, path);
  for (const char* property : kPlyVertexProperties) expectLine(in, property, path);
  std::string line;
  if (!nextHeaderLine(in, &line)) throwPlyError(path, "the header ends after the vertices");
  if (line == kPlyColourProperties[0]) {
    counts.colours = true;
    expectLine(in, kPlyColourProperties[1], path);
    expectLine(in, kPlyColourProperties[2], path);
    if (!nextHeaderLine(in, &line)) throwPlyError(path, "the header ends after the vertices");
  }
  std::istringstream face_line(line + "\n");
  counts.faces = expectCount(face_line, kPlyFaceHeader, path);
  expectLine(in, "property list uchar int vertex_indices", path);
  expectLine(in, "end_header", path);
  return counts;
}

void decodeVertices(const char* bytes, size_t count, bool colours, TriangleMesh* mesh) {
  mesh->vertices_W.resize(count);
  if (colours) mesh->colours_rgb.resize(count);
  for (size_t v = 0; v < count; ++v) {
    for (int axis = 0; axis < 3; ++axis) {
      mesh->vertices_W[v][axis] = bitsToFloat(readLittleEndian(bytes + 4 * axis));
    }
    bytes += kPlyVertexBytes;
    if (!colours) continue;
    for (int c = 0; c < 3; ++c) mesh->colours_rgb[v][c] = static_cast<uint8_t>(bytes[c]);
    bytes += kPlyColourBytes;
  }
}

std::vector<Eigen::Vector3i> decodeFaces(const char* bytes, size_t count, size_t vertex_count,
                                         const std::string& path) {
  std::vector<Eigen::Vector3i> faces(count);
  for (size_t f = 0; f < count; ++f, bytes += kPlyFaceBytes) {
    if (bytes[0] != 3) throwPlyError(path, "face " + std::to_string(f) + " is not a triangle");
    for (int k = 0; k < 3; ++k) {
      faces[f][k] = static_cast<int>(readLittleEndian(bytes + 1 + 4 * k));
    }
    if (!areIndicesValid(faces[f], vertex_count)) {
      throwPlyError(path, "face " + std::to_string(f) + " references a vertex out of range");
    }
  }
  return faces;
}

}  // namespace

void writePly(const std::string& path, const TriangleMesh& mesh) {
  for (size_t f = 0; f < mesh.faces.size(); ++f) {
    if (!areIndicesValid(mesh.faces[f], mesh.vertices_W.size())) {
      throwPlyError(path, "face " + std::to_string(f) + " references a vertex out of range");
    }
  }
  if (!mesh.colours_rgb.empty() && mesh.colours_rgb.size() != mesh.vertices_W.size()) {
    throwPlyError(path, "the mesh has " + std::to_string(mesh.colours_rgb.size()) +
                            " colours for " + std::to_string(mesh.vertices_W.size()) + " vertices");
  }
  std::ofstream out(path, std::ios::binary | std::ios::trunc);
  if (!out) throwPlyError(path, "cannot open for writing");
  const std::string header = plyHeader(mesh);
  const std::string body = plyBody(mesh);
  out.write(header.data(), static_cast<std::streamsize>(header.size()));
  out.write(body.data(), static_cast<std::streamsize>(body.size()));
  out.close();
  if (!out) throwPlyError(path, "write failed");
}

TriangleMesh readPly(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) throwPlyError(path, "cannot open for reading");
  const PlyCounts counts = readPlyHeader(in, path);
  const std::string body((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  // Counts come from the file; compare without overflowing before trusting them.
  const size_t vertex_bytes = kPlyVertexBytes + (counts.colours ? kPlyColourBytes : 0);
  const size_t max_count = body.size() / std::min(vertex_bytes, kPlyFaceBytes);
  if (counts.vertices > max_count || counts.faces > max_count ||
      body.size() != counts.vertices * vertex_bytes + counts.faces * kPlyFaceBytes) {
    throwPlyError(path, "data size does not match the header's element counts");
  }
  TriangleMesh mesh;
  decodeVertices(body.data(), counts.vertices, counts.colours, &mesh);
  mesh.faces = decodeFaces(body.data() + counts.vertices * vertex_bytes, counts.faces,
                           counts.vertices, path);
  return mesh;
}

}  // namespace sift_hull
