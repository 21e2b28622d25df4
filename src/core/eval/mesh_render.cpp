#include "sift_hull/eval/mesh_render.h"

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

/// std::llround of a value within +-2^29, without the library call.
int64_t roundedFixed(double value) {
  return value >= 0.0 ? static_cast<int64_t>(value + 0.5) : -static_cast<int64_t>(0.5 - value);
}

/// Calls visit(v, depth, x, y) for each vertex v of `mesh` in front of `camera` whose pixel lies
/// within +-kMaxProjectedPx: its depth and its pixel in fixed point (kSubpixelScale).
template <typename Visit>
void forEachProjectedVertex(const TriangleMesh& mesh, const PinholeCamera& camera,
                            const Visit& visit) {
  // Without distortion, P = K [R | t] directly: its last row gives the depth (K's is (0, 0, 1)).
  const bool ideal = !camera.distorted();
  const Matrix34d P = camera.projectionMatrix();
  for (size_t v = 0; v < mesh.vertices_W.size(); ++v) {
    const Eigen::Vector3d X_W = mesh.vertices_W[v].cast<double>();
    Eigen::Vector2d pixel;
    double depth = 0.0;
    if (ideal) {
      const Eigen::Vector3d p = P.leftCols<3>() * X_W + P.col(3);
      depth = p.z();
      if (!(depth > 0.0)) continue;
      pixel = p.head<2>() / depth;
    } else {
      depth = camera.depth(X_W);
      if (!(depth > 0.0)) continue;
      pixel = camera.project(X_W);
    }
    if (!(pixel.cwiseAbs().maxCoeff() <= kMaxProjectedPx)) continue;
    visit(v, depth, roundedFixed(pixel.x() * kSubpixelScale),
          roundedFixed(pixel.y() * kSubpixelScale));
  }
}

std::vector<ProjectedVertex> projectVertices(const TriangleMesh& mesh,
                                             const PinholeCamera& camera) {
  std::vector<ProjectedVertex> projected(mesh.vertices_W.size());
  forEachProjectedVertex(mesh, camera, [&](size_t v, double depth, int64_t x, int64_t y) {
    projected[v] = {{x, y}, depth, true};
  });
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
  // Pixel centres at integer coordinates: the first at or after min_fixed, the last at or before
  // max_fixed (arithmetic shifts round towards minus infinity).
  const int64_t first = -((-min_fixed) >> kSubpixelBits);
  const int64_t last = max_fixed >> kSubpixelBits;
  return {static_cast<int>(std::max<int64_t>(first, 0)),
          static_cast<int>(std::min<int64_t>(last, pixels - 1))};
}

// Calls visit(column, row, weights) for every pixel centre the triangle covers; weights are the
// barycentric coordinates of the centre with respect to corners[0..2].
template <typename Visit>
void rasteriseTriangle(const std::array<FixedPoint, 3>& corners, cv::Size size, Visit&& visit) {
  // The pixel centres of the bounding box first: most faces of a fine mesh hold none.
  const PixelRange columns =
      coveredRange(std::min({corners[0].x, corners[1].x, corners[2].x}),
                   std::max({corners[0].x, corners[1].x, corners[2].x}), size.width);
  if (columns.first > columns.last) return;
  const PixelRange rows =
      coveredRange(std::min({corners[0].y, corners[1].y, corners[2].y}),
                   std::max({corners[0].y, corners[1].y, corners[2].y}), size.height);
  if (rows.first > rows.last) return;
  std::array<int, 3> order = {0, 1, 2};
  int64_t doubled_area = edgeFunction(corners[0], corners[1], corners[2]);
  if (doubled_area == 0) return;
  if (doubled_area < 0) std::swap(order[1], order[2]);
  doubled_area = std::abs(doubled_area);
  const FixedPoint& a = corners[order[0]];
  const FixedPoint& b = corners[order[1]];
  const FixedPoint& c = corners[order[2]];
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

cv::Mat rasteriseMask(const TriangleMesh& mesh, const PinholeCamera& camera, cv::Size size,
                      bool closed, bool faces_checked) {
  requireImageSize(size, "rasteriseMask");
  if (!faces_checked) requireValidFaces(mesh, "rasteriseMask");
  cv::Mat mask = cv::Mat::zeros(size, CV_8UC1);
  const auto fill = [&mask](int column, int row, const std::array<double, 3>&) {
    mask.at<uchar>(row, column) = 255;
  };
  // The projected vertices in 8 bytes each (a fine mesh's faces are mostly read for nothing but
  // their corners: the memory they take sets the pace); x = kUnusable where projectVertices would
  // call the vertex not usable.
  constexpr int32_t kUnusable = std::numeric_limits<int32_t>::min();
  std::vector<std::array<int32_t, 2>> corners_px(mesh.vertices_W.size(), {kUnusable, 0});
  forEachProjectedVertex(mesh, camera, [&](size_t v, double, int64_t x, int64_t y) {
    corners_px[v] = {static_cast<int32_t>(x), static_cast<int32_t>(y)};
  });
  for (const Eigen::Vector3i& face : mesh.faces) {
    const std::array<int32_t, 2>& a = corners_px[face[0]];
    const std::array<int32_t, 2>& b = corners_px[face[1]];
    const std::array<int32_t, 2>& c = corners_px[face[2]];
    if (a[0] == kUnusable || b[0] == kUnusable || c[0] == kUnusable) continue;
    if (closed &&
        int64_t{b[0] - a[0]} * (c[1] - a[1]) - int64_t{b[1] - a[1]} * (c[0] - a[0]) <= 0) {
      continue;  // turned the other way: a face turned this way covers its pixels
    }
    rasteriseTriangle(std::array<FixedPoint, 3>{FixedPoint{a[0], a[1]}, FixedPoint{b[0], b[1]},
                                                FixedPoint{c[0], c[1]}},
                      size, fill);
  }
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
