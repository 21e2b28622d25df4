#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <fstream>
#include <functional>
#include <iterator>
#include <limits>
#include <opencv2/imgproc.hpp>
#include <random>
#include <set>
#include <stdexcept>
#include <string>
#include <tuple>
#include <utility>

#include "sift_hull/mesh.h"

namespace sift_hull {
namespace {

constexpr double kPi = 3.14159265358979323846;

using ScalarField = std::function<double(const Eigen::Vector3d&)>;

FieldSampler samplerOf(const ScalarField& field) {
  return [field](const std::vector<Eigen::Vector3d>& points_W, std::vector<float>* values) {
    values->resize(points_W.size());
    for (size_t i = 0; i < points_W.size(); ++i)
      (*values)[i] = static_cast<float>(field(points_W[i]));
  };
}

/// The cells of the grid over [low, low + count * edge] whose corners straddle zero under the
/// same rule (value >= 0 outside) and float precision marching cubes uses.
SurfaceCells straddlingCells(const ScalarField& field, const Eigen::Vector3d& low, int count,
                             double edge) {
  const int points = count + 1;
  std::vector<bool> outside(static_cast<size_t>(points) * points * points);
  const auto at = [points](int i, int j, int k) {
    return (static_cast<size_t>(k) * points + j) * points + i;
  };
  for (int k = 0; k < points; ++k) {
    for (int j = 0; j < points; ++j) {
      for (int i = 0; i < points; ++i) {
        const Eigen::Vector3d p = low + edge * Eigen::Vector3d(i, j, k);
        outside[at(i, j, k)] = static_cast<float>(field(p)) >= 0.0f;
      }
    }
  }
  SurfaceCells cells;
  cells.origin_W = low;
  cells.cell_edge_m = edge;
  for (int k = 0; k < count; ++k) {
    for (int j = 0; j < count; ++j) {
      for (int i = 0; i < count; ++i) {
        int outside_corners = 0;
        for (int c = 0; c < 8; ++c)
          outside_corners += outside[at(i + (c & 1), j + ((c >> 1) & 1), k + (c >> 2))];
        if (outside_corners > 0 && outside_corners < 8) cells.cells.emplace_back(i, j, k);
      }
    }
  }
  return cells;
}

/// V - E + F over the vertices faces use: 2 for a sphere, 0 for a torus.
long eulerCharacteristic(const TriangleMesh& mesh) {
  std::set<int> used_vertices;
  std::set<std::pair<int, int>> edges;
  for (const Eigen::Vector3i& face : mesh.faces) {
    for (int k = 0; k < 3; ++k) {
      used_vertices.insert(face[k]);
      edges.insert(std::minmax(face[k], face[(k + 1) % 3]));
    }
  }
  return static_cast<long>(used_vertices.size()) - static_cast<long>(edges.size()) +
         static_cast<long>(mesh.faces.size());
}

double smallestFaceArea(const TriangleMesh& mesh) {
  double smallest = std::numeric_limits<double>::infinity();
  for (const Eigen::Vector3i& face : mesh.faces) {
    const Eigen::Vector3d v0 = mesh.vertices_W[face[0]].cast<double>();
    const Eigen::Vector3d v1 = mesh.vertices_W[face[1]].cast<double>();
    const Eigen::Vector3d v2 = mesh.vertices_W[face[2]].cast<double>();
    smallest = std::min(smallest, 0.5 * (v1 - v0).cross(v2 - v0).norm());
  }
  return smallest;
}

const Eigen::Vector3d kSphereCentre(0.013, -0.021, 0.007);
constexpr double kSphereRadius = 1.0;
constexpr double kCellEdge = 0.05;

double sphereField(const Eigen::Vector3d& p) { return (p - kSphereCentre).norm() - kSphereRadius; }

TriangleMesh sphereMesh() {
  const SurfaceCells cells =
      straddlingCells(sphereField, Eigen::Vector3d::Constant(-1.2),
                      static_cast<int>(std::lround(2.4 / kCellEdge)), kCellEdge);
  return marchingCubes(cells, samplerOf(sphereField));
}

/// A tetrahedron with outward faces.
TriangleMesh tetrahedron() {
  TriangleMesh mesh;
  mesh.vertices_W = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {0, 0, 1}};
  mesh.faces = {{0, 2, 1}, {0, 1, 3}, {0, 3, 2}, {1, 2, 3}};
  return mesh;
}

/// Looks along +z from 4 units away at a point a little off the sphere's centre.
PinholeCamera sphereCamera() {
  Eigen::Matrix3d K;
  K << 500.0, 0.0, 161.5, 0.0, 520.0, 118.0, 0.0, 0.0, 1.0;
  const Eigen::Matrix3d R =
      Eigen::AngleAxisd(0.05, Eigen::Vector3d(1.0, -2.0, 0.5).normalized()).toRotationMatrix();
  const Eigen::Vector3d centre = kSphereCentre - 4.0 * R.row(2).transpose();
  return PinholeCamera::fromCentre(K, R, centre);
}

/// A camera at the origin looking along +z that maps (x, y, 1) to pixel (x, y).
PinholeCamera unitCamera() {
  return PinholeCamera(Eigen::Matrix3d::Identity(), Eigen::Matrix3d::Identity(),
                       Eigen::Vector3d::Zero());
}

void expectWatertight(const TriangleMesh& mesh) {
  const MeshCheck check = checkMesh(mesh);
  EXPECT_TRUE(check.watertight);
  EXPECT_EQ(check.boundary_edges, 0u);
  EXPECT_EQ(check.non_manifold_edges, 0u);
  EXPECT_EQ(check.misoriented_edges, 0u);
  EXPECT_EQ(check.degenerate_faces, 0u);
}

TEST(MarchingCubesTest, SphereIsClosedOutwardAndClose) {
  const TriangleMesh mesh = sphereMesh();
  ASSERT_FALSE(mesh.faces.empty());
  expectWatertight(mesh);
  EXPECT_EQ(eulerCharacteristic(mesh), 2);
  const double exact = 4.0 / 3.0 * kPi * std::pow(kSphereRadius, 3);
  const double volume = meshVolume(mesh);
  EXPECT_GT(volume, 0.0);
  EXPECT_NEAR(volume, exact, 0.01 * exact);
  // Linear interpolation of a distance field along an edge errs by at most edge^2 / (8 radius).
  const double tolerance = kCellEdge * kCellEdge / (4.0 * kSphereRadius);
  double worst = 0.0;
  for (const Eigen::Vector3f& vertex : mesh.vertices_W) {
    worst = std::max(worst, std::abs(sphereField(vertex.cast<double>())));
  }
  EXPECT_LT(worst, tolerance);
}

TEST(MarchingCubesTest, SamplesEachCornerOnceInOneCall) {
  SurfaceCells cells;
  cells.cell_edge_m = 0.5;
  for (int i = 0; i < 8; ++i) cells.cells.emplace_back(i & 1, (i >> 1) & 1, i >> 2);
  int calls = 0;
  std::set<std::tuple<double, double, double>> distinct;
  size_t points = 0;
  const FieldSampler counting = [&](const std::vector<Eigen::Vector3d>& points_W,
                                    std::vector<float>* values) {
    ++calls;
    points += points_W.size();
    for (const Eigen::Vector3d& p : points_W) distinct.emplace(p.x(), p.y(), p.z());
    values->clear();
    for (const Eigen::Vector3d& p : points_W)
      values->push_back(static_cast<float>((p - Eigen::Vector3d::Constant(0.5)).norm() - 0.3));
  };
  const TriangleMesh mesh = marchingCubes(cells, counting);
  EXPECT_EQ(calls, 1);
  EXPECT_EQ(points, 27u);
  EXPECT_EQ(distinct.size(), 27u);
  expectWatertight(mesh);
}

TEST(MarchingCubesTest, ShiftedAndRepeatedCellsGiveTheSameSurface) {
  SurfaceCells cells = straddlingCells(sphereField, Eigen::Vector3d::Constant(-1.2), 48, kCellEdge);
  const TriangleMesh reference = marchingCubes(cells, samplerOf(sphereField));
  // Negative indices with the origin moved to match, and every cell listed twice.
  const Eigen::Vector3i shift(-30, -31, -32);
  cells.origin_W -= kCellEdge * shift.cast<double>();
  for (Eigen::Vector3i& cell : cells.cells) cell += shift;
  cells.cells.insert(cells.cells.end(), cells.cells.begin(), cells.cells.end());
  const TriangleMesh shifted = marchingCubes(cells, samplerOf(sphereField));
  expectWatertight(shifted);
  EXPECT_EQ(shifted.faces.size(), reference.faces.size());
  EXPECT_NEAR(meshVolume(shifted), meshVolume(reference), 1e-5);
}

TEST(MarchingCubesTest, BoxIsWatertight) {
  const Eigen::Vector3d half(0.7, 0.5, 0.3), centre(0.02, -0.03, 0.01);
  const ScalarField box = [&](const Eigen::Vector3d& p) {
    return ((p - centre).cwiseAbs() - half).maxCoeff();
  };
  const TriangleMesh mesh = marchingCubes(
      straddlingCells(box, Eigen::Vector3d::Constant(-1.0), 40, kCellEdge), samplerOf(box));
  expectWatertight(mesh);
  EXPECT_EQ(eulerCharacteristic(mesh), 2);
  // Cells cut by the box's edges lose at most half a cell face of cross-section along them.
  const double edge_length = 4.0 * 2.0 * half.sum();
  EXPECT_NEAR(meshVolume(mesh), 8.0 * half.prod(), edge_length * kCellEdge * kCellEdge);
}

TEST(MarchingCubesTest, TorusIsWatertightWithGenusOne) {
  const ScalarField torus = [](const Eigen::Vector3d& p) {
    return std::hypot(std::hypot(p.x(), p.y()) - 1.0, p.z()) - 0.3;
  };
  const TriangleMesh mesh =
      marchingCubes(straddlingCells(torus, Eigen::Vector3d(-1.41, -1.42, -0.43), 57, kCellEdge),
                    samplerOf(torus));
  expectWatertight(mesh);
  EXPECT_EQ(eulerCharacteristic(mesh), 0);
  const double exact = 2.0 * kPi * kPi * 1.0 * 0.3 * 0.3;
  EXPECT_NEAR(meshVolume(mesh), exact, 0.02 * exact);
}

TEST(MarchingCubesTest, CornersExactlyOnTheSurfaceKeepItWatertight) {
  // Grid points (3,0,0), (2,2,1) etc. times 0.25 lie exactly on the sphere of radius 0.75.
  const ScalarField sphere = [](const Eigen::Vector3d& p) { return p.norm() - 0.75; };
  const TriangleMesh mesh = marchingCubes(
      straddlingCells(sphere, Eigen::Vector3d::Constant(-1.25), 10, 0.25), samplerOf(sphere));
  expectWatertight(mesh);
  EXPECT_EQ(eulerCharacteristic(mesh), 2);
  EXPECT_GT(meshVolume(mesh), 0.0);
  // Vertices stay off the zero corners, so no two of a face coincide.
  EXPECT_GT(smallestFaceArea(mesh), 0.0);
}

TEST(MarchingCubesTest, RandomFieldWithAmbiguousCellsIsWatertight) {
  constexpr int kPoints = 14;
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> value(-1.0, 1.0);
  std::vector<double> grid(kPoints * kPoints * kPoints);
  for (double& v : grid) v = value(rng);
  // Positive on the grid's border, so that the surface closes inside it.
  const ScalarField field = [&grid](const Eigen::Vector3d& p) {
    const Eigen::Vector3i index = p.array().round().cast<int>().matrix();
    if (index.minCoeff() <= 0 || index.maxCoeff() >= kPoints - 1) return 1.0;
    return grid[(index.z() * kPoints + index.y()) * kPoints + index.x()];
  };
  const TriangleMesh mesh = marchingCubes(
      straddlingCells(field, Eigen::Vector3d::Zero(), kPoints - 1, 1.0), samplerOf(field));
  ASSERT_GT(mesh.faces.size(), 1000u);
  expectWatertight(mesh);
  EXPECT_GT(meshVolume(mesh), 0.0);
}

TEST(MarchingCubesTest, EmptyCellListGivesEmptyMesh) {
  bool called = false;
  const TriangleMesh mesh = marchingCubes(
      SurfaceCells(),
      [&called](const std::vector<Eigen::Vector3d>&, std::vector<float>*) { called = true; });
  EXPECT_TRUE(mesh.vertices_W.empty());
  EXPECT_TRUE(mesh.faces.empty());
  EXPECT_FALSE(called);
}

TEST(MarchingCubesTest, RejectsAFieldReturningTheWrongCount) {
  SurfaceCells cells;
  cells.cells.emplace_back(0, 0, 0);
  EXPECT_THROW(marchingCubes(cells, [](const std::vector<Eigen::Vector3d>&,
                                       std::vector<float>* values) { values->assign(3, 1.0f); }),
               std::runtime_error);
  cells.cell_edge_m = 0.0;
  EXPECT_THROW(marchingCubes(cells, samplerOf(sphereField)), std::invalid_argument);
}

TEST(CheckMeshTest, EmptyMeshIsNotWatertight) {
  EXPECT_FALSE(checkMesh(TriangleMesh()).watertight);
}

TEST(CheckMeshTest, DetectsMissingFlippedDuplicatedAndDegenerateFaces) {
  expectWatertight(tetrahedron());

  TriangleMesh missing = tetrahedron();
  missing.faces.pop_back();
  EXPECT_FALSE(checkMesh(missing).watertight);
  EXPECT_EQ(checkMesh(missing).boundary_edges, 3u);

  TriangleMesh flipped = tetrahedron();
  std::swap(flipped.faces[0][1], flipped.faces[0][2]);
  EXPECT_FALSE(checkMesh(flipped).watertight);
  EXPECT_EQ(checkMesh(flipped).misoriented_edges, 3u);

  TriangleMesh duplicated = tetrahedron();
  duplicated.faces.push_back(duplicated.faces[0]);
  EXPECT_FALSE(checkMesh(duplicated).watertight);
  EXPECT_EQ(checkMesh(duplicated).non_manifold_edges, 3u);

  TriangleMesh degenerate = tetrahedron();
  degenerate.faces.emplace_back(1, 1, 2);
  EXPECT_FALSE(checkMesh(degenerate).watertight);
  EXPECT_EQ(checkMesh(degenerate).degenerate_faces, 1u);
  EXPECT_EQ(checkMesh(degenerate).boundary_edges, 0u);
}

TEST(MeshVolumeTest, TetrahedronHasSignedVolume) {
  TriangleMesh mesh = tetrahedron();
  EXPECT_NEAR(meshVolume(mesh), 1.0 / 6.0, 1e-12);
  for (Eigen::Vector3i& face : mesh.faces) std::swap(face[1], face[2]);
  EXPECT_NEAR(meshVolume(mesh), -1.0 / 6.0, 1e-12);
  EXPECT_EQ(meshVolume(TriangleMesh()), 0.0);
}

TEST(PlyTest, RoundTripIsExact) {
  const TriangleMesh mesh = sphereMesh();
  const std::string path = ::testing::TempDir() + "/test_mesh_round_trip.ply";
  writePly(path, mesh);
  const TriangleMesh read = readPly(path);
  ASSERT_EQ(read.vertices_W.size(), mesh.vertices_W.size());
  ASSERT_EQ(read.faces.size(), mesh.faces.size());
  EXPECT_TRUE(std::equal(mesh.vertices_W.begin(), mesh.vertices_W.end(), read.vertices_W.begin()));
  EXPECT_TRUE(std::equal(mesh.faces.begin(), mesh.faces.end(), read.faces.begin()));

  writePly(path, TriangleMesh());
  const TriangleMesh empty = readPly(path);
  EXPECT_TRUE(empty.vertices_W.empty());
  EXPECT_TRUE(empty.faces.empty());
}

void expectReadFailureNamingPath(const std::string& path) {
  try {
    readPly(path);
    ADD_FAILURE() << "readPly accepted " << path;
  } catch (const std::runtime_error& error) {
    EXPECT_EQ(std::string(error.what()).rfind(path + ": ", 0), 0u) << error.what();
  }
}

TEST(PlyTest, RejectsMissingTextAndTruncatedFiles) {
  const std::string directory = ::testing::TempDir();
  expectReadFailureNamingPath(directory + "/test_mesh_does_not_exist.ply");

  const std::string text_path = directory + "/test_mesh_text.ply";
  std::ofstream(text_path) << "ply\nformat ascii 1.0\nelement vertex 1\nproperty float x\n"
                              "property float y\nproperty float z\nelement face 0\n"
                              "property list uchar int vertex_indices\nend_header\n0 0 0\n";
  expectReadFailureNamingPath(text_path);

  const std::string truncated_path = directory + "/test_mesh_truncated.ply";
  writePly(truncated_path, tetrahedron());
  std::ifstream in(truncated_path, std::ios::binary);
  const std::string bytes((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  in.close();
  std::ofstream(truncated_path, std::ios::binary) << bytes.substr(0, bytes.size() - 1);
  expectReadFailureNamingPath(truncated_path);

  EXPECT_THROW(writePly(directory + "/no_such_directory/mesh.ply", tetrahedron()),
               std::runtime_error);
}

TEST(RasteriseTest, SphereMaskMatchesTheProjectedDisc) {
  const TriangleMesh mesh = sphereMesh();
  const PinholeCamera camera = sphereCamera();
  const cv::Size size(320, 240);
  const cv::Mat mask = rasteriseMask(mesh, camera, size);
  ASSERT_EQ(mask.type(), CV_8UC1);
  ASSERT_EQ(mask.size(), size);
  const Eigen::Vector3d to_centre = kSphereCentre - camera.centre();
  int both = 0, either = 0, holes = 0;
  for (int v = 0; v < size.height; ++v) {
    for (int u = 0; u < size.width; ++u) {
      const Eigen::Vector3d ray = camera.rayDirection(Eigen::Vector2d(u, v));
      const double miss = (to_centre - to_centre.dot(ray) * ray).norm();
      const bool in_disc = miss < kSphereRadius;
      const bool in_mask = mask.at<uchar>(v, u) == 255;
      both += in_disc && in_mask;
      either += in_disc || in_mask;
      // Well inside the outline every pixel must be covered: no cracks between faces.
      holes += miss < 0.9 * kSphereRadius && !in_mask;
    }
  }
  ASSERT_GT(either, 10000);
  EXPECT_GE(static_cast<double>(both) / either, 0.98);
  EXPECT_EQ(holes, 0);
}

TEST(RasteriseTest, PixelsOnASharedEdgeBelongToOneTriangle) {
  // A square from (2, 2) to (12, 12) split along its diagonal through pixel centres.
  TriangleMesh first, second, square;
  square.vertices_W = {{2, 2, 1}, {12, 2, 1}, {12, 12, 1}, {2, 12, 1}};
  first.vertices_W = second.vertices_W = square.vertices_W;
  first.faces = {{0, 1, 2}};
  second.faces = {{0, 2, 3}};
  square.faces = {{0, 1, 2}, {0, 2, 3}};
  const cv::Size size(16, 16);
  const int first_count = cv::countNonZero(rasteriseMask(first, unitCamera(), size));
  const int second_count = cv::countNonZero(rasteriseMask(second, unitCamera(), size));
  EXPECT_EQ(first_count + second_count,
            cv::countNonZero(rasteriseMask(square, unitCamera(), size)));
  // Two of the four sides are half-open, as with the pixels of [2, 12) x [2, 12).
  EXPECT_EQ(first_count + second_count, 100);
}

TEST(RasteriseTest, SkipsFacesBehindTheCamera) {
  TriangleMesh mesh;
  mesh.vertices_W = {{2, 2, -1}, {12, 2, 1}, {12, 12, 1}};
  mesh.faces = {{0, 1, 2}};
  EXPECT_EQ(cv::countNonZero(rasteriseMask(mesh, unitCamera(), cv::Size(16, 16))), 0);
}

TEST(RenderShadedTest, SphereIsLitAtItsCentreAndBlackAtTheCorner) {
  const PinholeCamera camera = sphereCamera();
  const cv::Mat image = renderShaded(sphereMesh(), camera, cv::Size(320, 240));
  ASSERT_EQ(image.type(), CV_8UC3);
  const Eigen::Vector2d centre = camera.project(kSphereCentre);
  const cv::Vec3b at_centre = image.at<cv::Vec3b>(static_cast<int>(std::lround(centre.y())),
                                                  static_cast<int>(std::lround(centre.x())));
  // Facing the camera head-on gives nearly full brightness.
  EXPECT_GT(at_centre[0], 240);
  EXPECT_EQ(image.at<cv::Vec3b>(0, 0), cv::Vec3b(0, 0, 0));
  EXPECT_EQ(cv::countNonZero(renderShaded(TriangleMesh(), camera, cv::Size(8, 8)).reshape(1)), 0);
}

TEST(RenderShadedTest, NearerFaceHidesFartherOneInEitherOrder) {
  // A square facing the camera at depth 2 and a larger one behind it tilted by 45 degrees.
  TriangleMesh mesh;
  mesh.vertices_W = {{-1, -1, 2}, {1, -1, 2}, {1, 1, 2}, {-1, 1, 2},
                     {-3, -3, 1}, {3, -3, 1}, {3, 3, 7}, {-3, 3, 7}};
  Eigen::Matrix3d K;
  K << 20.0, 0.0, 20.0, 0.0, 20.0, 20.0, 0.0, 0.0, 1.0;
  const PinholeCamera camera(K, Eigen::Matrix3d::Identity(), Eigen::Vector3d::Zero());
  for (bool front_first : {true, false}) {
    const std::vector<Eigen::Vector3i> front = {{0, 1, 2}, {0, 2, 3}},
                                       back = {{4, 5, 6}, {4, 6, 7}};
    mesh.faces = front_first ? front : back;
    mesh.faces.insert(mesh.faces.end(), (front_first ? back : front).begin(),
                      (front_first ? back : front).end());
    const cv::Mat image = renderShaded(mesh, camera, cv::Size(41, 41));
    const uchar at_front = image.at<cv::Vec3b>(20, 20)[0];
    const uchar at_back = image.at<cv::Vec3b>(20, 33)[0];
    // The front square is seen nearly head-on (grey 249), the back faces at 30 degrees or more
    // (grey 225 and 161), so the back faces would show if drawn over the front one.
    EXPECT_GT(at_front, 240) << "front first: " << front_first;
    EXPECT_GT(at_back, 0) << "front first: " << front_first;
    EXPECT_LT(at_back, 230) << "front first: " << front_first;
  }
}

TEST(RenderTurntableTest, TilesTwoPerRowAndPadsWithBlack) {
  const cv::Size tile(80, 60);
  const cv::Mat sheet = renderTurntable(sphereMesh(), 3, tile);
  ASSERT_EQ(sheet.type(), CV_8UC3);
  ASSERT_EQ(sheet.size(), cv::Size(160, 120));
  for (int view = 0; view < 3; ++view) {
    const cv::Mat rendered = sheet(cv::Rect((view % 2) * 80, (view / 2) * 60, 80, 60));
    EXPECT_GT(rendered.at<cv::Vec3b>(30, 40)[0], 0) << "view " << view;
    EXPECT_EQ(rendered.at<cv::Vec3b>(0, 0), cv::Vec3b(0, 0, 0)) << "view " << view;
    // The outline spans about 80 % of the tile's height.
    cv::Mat grey;
    cv::extractChannel(rendered, grey, 0);
    const cv::Rect bounds = cv::boundingRect(grey);
    EXPECT_NEAR(bounds.height, 0.8 * 60, 3.0) << "view " << view;
  }
  EXPECT_EQ(cv::countNonZero(sheet(cv::Rect(80, 60, 80, 60)).reshape(1)), 0);
}

TEST(RenderTurntableTest, EmptyMeshGivesABlackSheet) {
  const cv::Mat sheet = renderTurntable(TriangleMesh(), 4, cv::Size(32, 24));
  ASSERT_EQ(sheet.size(), cv::Size(64, 48));
  EXPECT_EQ(cv::countNonZero(sheet.reshape(1)), 0);
  EXPECT_THROW(renderTurntable(TriangleMesh(), 0, cv::Size(32, 24)), std::invalid_argument);
}

}  // namespace
}  // namespace sift_hull
