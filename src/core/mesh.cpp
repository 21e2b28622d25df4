#include "sift_hull/mesh.h"

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
#include <stdexcept>
#include <string>

namespace sift_hull {
namespace {

bool isIndexValid(int index, size_t vertex_count) {
  return index >= 0 && static_cast<size_t>(index) < vertex_count;
}

bool areIndicesValid(const Eigen::Vector3i& face, size_t vertex_count) {
  return isIndexValid(face[0], vertex_count) && isIndexValid(face[1], vertex_count) &&
         isIndexValid(face[2], vertex_count);
}

void requireValidFaces(const TriangleMesh& mesh, const std::string& context) {
  for (size_t f = 0; f < mesh.faces.size(); ++f) {
    if (!areIndicesValid(mesh.faces[f], mesh.vertices_W.size())) {
      throw std::invalid_argument(context + ": face " + std::to_string(f) +
                                  " references a vertex out of range");
    }
  }
}

// ---------------------------------------------------------------------------------------------
// Topology

bool isDegenerate(const Eigen::Vector3i& face, size_t vertex_count) {
  const bool repeats = face[0] == face[1] || face[1] == face[2] || face[2] == face[0];
  return repeats || !areIndicesValid(face, vertex_count);
}

// A face's edge as seen from its smaller vertex.
struct EdgeEnd {
  int larger;
  bool ascending;  ///< the face runs from the smaller vertex to the larger
};

// Edge ends of the non-degenerate faces grouped by their smaller vertex: the group of vertex v is
// ends[starts[v]] up to ends[starts[v + 1]]. Groups are small, so this replaces sorting all edges.
struct EdgeGroups {
  std::vector<size_t> starts;
  std::vector<EdgeEnd> ends;
};

EdgeGroups groupEdgesBySmallerVertex(const TriangleMesh& mesh) {
  const size_t vertex_count = mesh.vertices_W.size();
  EdgeGroups groups;
  groups.starts.assign(vertex_count + 1, 0);
  for (const Eigen::Vector3i& face : mesh.faces) {
    if (isDegenerate(face, vertex_count)) continue;
    for (int k = 0; k < 3; ++k) ++groups.starts[std::min(face[k], face[(k + 1) % 3]) + 1];
  }
  std::partial_sum(groups.starts.begin(), groups.starts.end(), groups.starts.begin());
  groups.ends.resize(groups.starts.back());
  std::vector<size_t> next(groups.starts.begin(), groups.starts.end() - 1);
  for (const Eigen::Vector3i& face : mesh.faces) {
    if (isDegenerate(face, vertex_count)) continue;
    for (int k = 0; k < 3; ++k) {
      const int from = face[k], to = face[(k + 1) % 3];
      groups.ends[next[std::min(from, to)]++] = {std::max(from, to), from < to};
    }
  }
  return groups;
}

void classifyEdge(size_t face_count, size_t ascending_count, MeshCheck* check) {
  if (face_count == 1) {
    ++check->boundary_edges;
  } else if (face_count >= 3) {
    ++check->non_manifold_edges;
  } else if (ascending_count != 1) {
    ++check->misoriented_edges;
  }
}

void classifyGroup(std::vector<EdgeEnd>::iterator first, std::vector<EdgeEnd>::iterator last,
                   MeshCheck* check) {
  std::sort(first, last, [](const EdgeEnd& a, const EdgeEnd& b) { return a.larger < b.larger; });
  while (first != last) {
    size_t faces = 0, ascending = 0;
    const int larger = first->larger;
    for (; first != last && first->larger == larger; ++first) {
      ++faces;
      ascending += first->ascending ? 1 : 0;
    }
    classifyEdge(faces, ascending, check);
  }
}

// ---------------------------------------------------------------------------------------------
// PLY

const char* const kPlyVertexHeader = "element vertex ";
const char* const kPlyFaceHeader = "element face ";
const std::array<const char*, 3> kPlyVertexProperties = {"property float x", "property float y",
                                                         "property float z"};
constexpr size_t kPlyVertexBytes = 3 * 4;
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
  header += kPlyFaceHeader + std::to_string(mesh.faces.size()) + "\n";
  header += "property list uchar int vertex_indices\nend_header\n";
  return header;
}

std::string plyBody(const TriangleMesh& mesh) {
  std::string body;
  body.reserve(mesh.vertices_W.size() * kPlyVertexBytes + mesh.faces.size() * kPlyFaceBytes);
  for (const Eigen::Vector3f& vertex : mesh.vertices_W) {
    for (int axis = 0; axis < 3; ++axis) appendLittleEndian(floatBits(vertex[axis]), &body);
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
  counts.faces = expectCount(in, kPlyFaceHeader, path);
  expectLine(in, "property list uchar int vertex_indices", path);
  expectLine(in, "end_header", path);
  return counts;
}

std::vector<Eigen::Vector3f> decodeVertices(const char* bytes, size_t count) {
  std::vector<Eigen::Vector3f> vertices(count);
  for (size_t v = 0; v < count; ++v, bytes += kPlyVertexBytes) {
    for (int axis = 0; axis < 3; ++axis) {
      vertices[v][axis] = bitsToFloat(readLittleEndian(bytes + 4 * axis));
    }
  }
  return vertices;
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

// ---------------------------------------------------------------------------------------------
// Rasterisation

// Projected vertices are snapped to 1/256 px so that edge functions are exact integers: two
// triangles sharing an edge then agree on which side of it every pixel centre lies.
constexpr int kSubpixelBits = 8;
constexpr int64_t kSubpixelScale = int64_t{1} << kSubpixelBits;
// Keeps the edge-function products within int64; faces reaching further out are skipped.
constexpr double kMaxProjectedPx = static_cast<double>(int64_t{1} << 21);

struct FixedPoint {
  int64_t x = 0;
  int64_t y = 0;
};

struct ProjectedVertex {
  FixedPoint pixel;
  double depth = 0.0;
  bool usable = false;
};

std::vector<ProjectedVertex> projectVertices(const TriangleMesh& mesh,
                                             const PinholeCamera& camera) {
  std::vector<ProjectedVertex> projected(mesh.vertices_W.size());
  for (size_t v = 0; v < projected.size(); ++v) {
    const Eigen::Vector3d X_W = mesh.vertices_W[v].cast<double>();
    projected[v].depth = camera.depth(X_W);
    if (!(projected[v].depth > 0.0)) continue;
    const Eigen::Vector2d pixel = camera.project(X_W);
    if (!(pixel.cwiseAbs().maxCoeff() <= kMaxProjectedPx)) continue;
    projected[v].pixel = {std::llround(pixel.x() * kSubpixelScale),
                          std::llround(pixel.y() * kSubpixelScale)};
    projected[v].usable = true;
  }
  return projected;
}

int64_t edgeFunction(const FixedPoint& a, const FixedPoint& b, const FixedPoint& p) {
  return (b.x - a.x) * (p.y - a.y) - (b.y - a.y) * (p.x - a.x);
}

// Pixel centres exactly on an edge go to the triangle for which the edge runs down the image (or
// leftwards when horizontal). After orienting both triangles alike, an edge they share runs
// opposite ways in them, so exactly one of the two takes such a pixel.
int64_t edgeBias(const FixedPoint& a, const FixedPoint& b) {
  const bool owns_boundary = b.y > a.y || (b.y == a.y && b.x < a.x);
  return owns_boundary ? 0 : 1;
}

struct PixelRange {
  int first = 0;
  int last = -1;
};

PixelRange coveredRange(int64_t min_fixed, int64_t max_fixed, int pixels) {
  const auto toPixel = [](int64_t fixed, bool up) {
    const double pixel = static_cast<double>(fixed) / kSubpixelScale;
    return static_cast<int64_t>(up ? std::ceil(pixel) : std::floor(pixel));
  };
  return {static_cast<int>(std::max<int64_t>(toPixel(min_fixed, true), 0)),
          static_cast<int>(std::min<int64_t>(toPixel(max_fixed, false), pixels - 1))};
}

// Calls visit(column, row, weights) for every pixel centre the triangle covers; weights are the
// barycentric coordinates of the centre with respect to corners[0..2].
template <typename Visit>
void rasteriseTriangle(const std::array<FixedPoint, 3>& corners, cv::Size size, Visit&& visit) {
  std::array<int, 3> order = {0, 1, 2};
  int64_t doubled_area = edgeFunction(corners[0], corners[1], corners[2]);
  if (doubled_area == 0) return;
  if (doubled_area < 0) std::swap(order[1], order[2]);
  doubled_area = std::abs(doubled_area);
  const FixedPoint& a = corners[order[0]];
  const FixedPoint& b = corners[order[1]];
  const FixedPoint& c = corners[order[2]];
  const PixelRange columns =
      coveredRange(std::min({a.x, b.x, c.x}), std::max({a.x, b.x, c.x}), size.width);
  const PixelRange rows =
      coveredRange(std::min({a.y, b.y, c.y}), std::max({a.y, b.y, c.y}), size.height);
  // Edge opposite each corner, and the bias implementing the boundary rule.
  const std::array<std::array<const FixedPoint*, 2>, 3> edges = {{{&b, &c}, {&c, &a}, {&a, &b}}};
  std::array<int64_t, 3> bias, step;
  for (int e = 0; e < 3; ++e) {
    bias[e] = edgeBias(*edges[e][0], *edges[e][1]);
    step[e] = -(edges[e][1]->y - edges[e][0]->y) * kSubpixelScale;
  }
  std::array<double, 3> weights;
  for (int row = rows.first; row <= rows.last; ++row) {
    const FixedPoint start = {columns.first * kSubpixelScale, row * kSubpixelScale};
    std::array<int64_t, 3> value;
    for (int e = 0; e < 3; ++e) value[e] = edgeFunction(*edges[e][0], *edges[e][1], start);
    for (int column = columns.first; column <= columns.last; ++column) {
      if (value[0] >= bias[0] && value[1] >= bias[1] && value[2] >= bias[2]) {
        for (int e = 0; e < 3; ++e)
          weights[order[e]] = static_cast<double>(value[e]) / doubled_area;
        visit(column, row, weights);
      }
      for (int e = 0; e < 3; ++e) value[e] += step[e];
    }
  }
}

// Calls draw(face index, corners) for every face whose vertices all project usably.
template <typename Draw>
void forEachProjectedFace(const TriangleMesh& mesh, const std::vector<ProjectedVertex>& projected,
                          Draw&& draw) {
  for (size_t f = 0; f < mesh.faces.size(); ++f) {
    const Eigen::Vector3i& face = mesh.faces[f];
    if (!projected[face[0]].usable || !projected[face[1]].usable || !projected[face[2]].usable) {
      continue;
    }
    draw(f, std::array<FixedPoint, 3>{projected[face[0]].pixel, projected[face[1]].pixel,
                                      projected[face[2]].pixel});
  }
}

void requireImageSize(cv::Size size, const std::string& context) {
  if (size.width < 0 || size.height < 0) {
    throw std::invalid_argument(context + ": negative image size");
  }
}

// ---------------------------------------------------------------------------------------------
// Shading and turntable

// Faces seen edge-on still get this grey, so that they stand out from the black background.
constexpr double kMinGrey = 48.0;

uchar faceGrey(const TriangleMesh& mesh, const Eigen::Vector3i& face,
               const Eigen::Vector3d& camera_centre) {
  const Eigen::Vector3d v0 = mesh.vertices_W[face[0]].cast<double>();
  const Eigen::Vector3d v1 = mesh.vertices_W[face[1]].cast<double>();
  const Eigen::Vector3d v2 = mesh.vertices_W[face[2]].cast<double>();
  const Eigen::Vector3d normal = (v1 - v0).cross(v2 - v0);
  const Eigen::Vector3d ray = (v0 + v1 + v2) / 3.0 - camera_centre;
  const double norms = normal.norm() * ray.norm();
  const double cosine = norms > 0.0 ? std::abs(normal.dot(ray)) / norms : 0.0;
  return cv::saturate_cast<uchar>(kMinGrey + (255.0 - kMinGrey) * cosine);
}

constexpr double kPi = 3.14159265358979323846;
constexpr double kTurntableElevationRad = 25.0 * kPi / 180.0;
// Fraction of the tile's smaller side the bounding sphere's outline spans.
constexpr double kTurntableFill = 0.8;

struct BoundingSphere {
  Eigen::Vector3d centre = Eigen::Vector3d::Zero();
  double radius = 0.0;
};

BoundingSphere boundingSphere(const TriangleMesh& mesh) {
  BoundingSphere sphere;
  if (mesh.vertices_W.empty()) return sphere;
  Eigen::Vector3d lowest = Eigen::Vector3d::Constant(std::numeric_limits<double>::infinity());
  Eigen::Vector3d highest = -lowest;
  for (const Eigen::Vector3f& vertex : mesh.vertices_W) {
    lowest = lowest.cwiseMin(vertex.cast<double>());
    highest = highest.cwiseMax(vertex.cast<double>());
  }
  sphere.centre = 0.5 * (lowest + highest);
  for (const Eigen::Vector3f& vertex : mesh.vertices_W) {
    sphere.radius = std::max(sphere.radius, (vertex.cast<double>() - sphere.centre).norm());
  }
  return sphere;
}

PinholeCamera turntableCamera(const BoundingSphere& sphere, double azimuth_rad, cv::Size tile) {
  const double focal_px = std::min(tile.width, tile.height);
  // The outline of a sphere seen from distance d spans a half-angle asin(radius / d).
  const double half_angle = std::atan(0.5 * kTurntableFill);
  const double distance = sphere.radius / std::sin(half_angle);
  Eigen::Matrix3d K;
  K << focal_px, 0.0, 0.5 * (tile.width - 1), 0.0, focal_px, 0.5 * (tile.height - 1), 0.0, 0.0, 1.0;
  const Eigen::Vector3d towards_camera(std::cos(kTurntableElevationRad) * std::cos(azimuth_rad),
                                       std::cos(kTurntableElevationRad) * std::sin(azimuth_rad),
                                       std::sin(kTurntableElevationRad));
  const Eigen::Vector3d forward = -towards_camera;
  const Eigen::Vector3d right = forward.cross(Eigen::Vector3d::UnitZ()).normalized();
  const Eigen::Vector3d down = forward.cross(right);
  Eigen::Matrix3d R;
  R.row(0) = right.transpose();
  R.row(1) = down.transpose();
  R.row(2) = forward.transpose();
  return PinholeCamera::fromCentre(K, R, sphere.centre + distance * towards_camera);
}

}  // namespace

MeshCheck checkMesh(const TriangleMesh& mesh) {
  MeshCheck check;
  check.degenerate_faces = static_cast<size_t>(std::count_if(
      mesh.faces.begin(), mesh.faces.end(),
      [&mesh](const Eigen::Vector3i& face) { return isDegenerate(face, mesh.vertices_W.size()); }));
  EdgeGroups groups = groupEdgesBySmallerVertex(mesh);
  for (size_t vertex = 0; vertex < mesh.vertices_W.size(); ++vertex) {
    classifyGroup(groups.ends.begin() + groups.starts[vertex],
                  groups.ends.begin() + groups.starts[vertex + 1], &check);
  }
  check.watertight = !mesh.faces.empty() && check.boundary_edges == 0 &&
                     check.non_manifold_edges == 0 && check.misoriented_edges == 0 &&
                     check.degenerate_faces == 0;
  return check;
}

double meshVolume(const TriangleMesh& mesh) {
  requireValidFaces(mesh, "meshVolume");
  double six_volume = 0.0;
  for (const Eigen::Vector3i& face : mesh.faces) {
    const Eigen::Vector3d v0 = mesh.vertices_W[face[0]].cast<double>();
    const Eigen::Vector3d v1 = mesh.vertices_W[face[1]].cast<double>();
    const Eigen::Vector3d v2 = mesh.vertices_W[face[2]].cast<double>();
    six_volume += v0.dot(v1.cross(v2));
  }
  return six_volume / 6.0;
}

void writePly(const std::string& path, const TriangleMesh& mesh) {
  for (size_t f = 0; f < mesh.faces.size(); ++f) {
    if (!areIndicesValid(mesh.faces[f], mesh.vertices_W.size())) {
      throwPlyError(path, "face " + std::to_string(f) + " references a vertex out of range");
    }
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
  const size_t max_count = body.size() / kPlyVertexBytes;
  if (counts.vertices > max_count || counts.faces > max_count ||
      body.size() != counts.vertices * kPlyVertexBytes + counts.faces * kPlyFaceBytes) {
    throwPlyError(path, "data size does not match the header's element counts");
  }
  TriangleMesh mesh;
  mesh.vertices_W = decodeVertices(body.data(), counts.vertices);
  mesh.faces = decodeFaces(body.data() + counts.vertices * kPlyVertexBytes, counts.faces,
                           counts.vertices, path);
  return mesh;
}

cv::Mat rasteriseMask(const TriangleMesh& mesh, const PinholeCamera& camera, cv::Size size) {
  requireImageSize(size, "rasteriseMask");
  requireValidFaces(mesh, "rasteriseMask");
  cv::Mat mask = cv::Mat::zeros(size, CV_8UC1);
  const auto fill = [&mask](int column, int row, const std::array<double, 3>&) {
    mask.at<uchar>(row, column) = 255;
  };
  forEachProjectedFace(mesh, projectVertices(mesh, camera),
                       [&](size_t, const std::array<FixedPoint, 3>& corners) {
                         rasteriseTriangle(corners, size, fill);
                       });
  return mask;
}

cv::Mat renderShaded(const TriangleMesh& mesh, const PinholeCamera& camera, cv::Size size) {
  requireImageSize(size, "renderShaded");
  requireValidFaces(mesh, "renderShaded");
  cv::Mat image = cv::Mat::zeros(size, CV_8UC3);
  // Inverse depth interpolates linearly in the image; larger is nearer, zero is the background.
  cv::Mat inverse_depth = cv::Mat::zeros(size, CV_64FC1);
  const std::vector<ProjectedVertex> projected = projectVertices(mesh, camera);
  const Eigen::Vector3d camera_centre = camera.centre();
  forEachProjectedFace(mesh, projected, [&](size_t f, const std::array<FixedPoint, 3>& corners) {
    const Eigen::Vector3i& face = mesh.faces[f];
    const uchar grey = faceGrey(mesh, face, camera_centre);
    const std::array<double, 3> corner_inverse_depth = {1.0 / projected[face[0]].depth,
                                                        1.0 / projected[face[1]].depth,
                                                        1.0 / projected[face[2]].depth};
    rasteriseTriangle(corners, size, [&](int column, int row, const std::array<double, 3>& w) {
      const double nearness = w[0] * corner_inverse_depth[0] + w[1] * corner_inverse_depth[1] +
                              w[2] * corner_inverse_depth[2];
      double& nearest = inverse_depth.at<double>(row, column);
      if (nearness <= nearest) return;
      nearest = nearness;
      image.at<cv::Vec3b>(row, column) = cv::Vec3b(grey, grey, grey);
    });
  });
  return image;
}

cv::Mat renderTurntable(const TriangleMesh& mesh, int views, cv::Size tile) {
  if (views < 1) throw std::invalid_argument("renderTurntable: views must be at least 1");
  if (tile.width < 1 || tile.height < 1) {
    throw std::invalid_argument("renderTurntable: tile size must be positive");
  }
  const int columns = std::min(views, 2);
  const int rows = (views + 1) / 2;
  cv::Mat sheet = cv::Mat::zeros(rows * tile.height, columns * tile.width, CV_8UC3);
  const BoundingSphere sphere = boundingSphere(mesh);
  // A mesh without extent has no visible area and no distance to frame it from.
  if (!(sphere.radius > 0.0 && std::isfinite(sphere.radius))) return sheet;
  for (int view = 0; view < views; ++view) {
    const PinholeCamera camera = turntableCamera(sphere, 2.0 * kPi * view / views, tile);
    const cv::Rect cell((view % 2) * tile.width, (view / 2) * tile.height, tile.width, tile.height);
    renderShaded(mesh, camera, tile).copyTo(sheet(cell));
  }
  return sheet;
}

}  // namespace sift_hull
