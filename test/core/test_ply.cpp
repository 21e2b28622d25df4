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

#include "common/mesh_fixtures.h"
#include "sift_hull/hull/mesh.h"
#include "sift_hull/io/ply.h"

namespace sift_hull {
namespace {

using namespace test;

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

TEST(PlyTest, ColoursRoundTripAfterTheCoordinatesAndMustBeOnePerVertex) {
  TriangleMesh mesh = sphereMesh();
  for (size_t v = 0; v < mesh.vertices_W.size(); ++v) {
    mesh.colours_rgb.push_back({static_cast<uint8_t>(v), static_cast<uint8_t>(255 - v % 256),
                                static_cast<uint8_t>(v * 7)});
  }
  const std::string path = ::testing::TempDir() + "/test_mesh_colours.ply";
  writePly(path, mesh);
  std::ifstream in(path, std::ios::binary);
  const std::string text((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  EXPECT_NE(text.find("property float z\nproperty uchar red\nproperty uchar green\n"
                      "property uchar blue\nelement face "),
            std::string::npos);
  const TriangleMesh read = readPly(path);
  EXPECT_TRUE(std::equal(mesh.vertices_W.begin(), mesh.vertices_W.end(), read.vertices_W.begin()));
  EXPECT_EQ(read.colours_rgb, mesh.colours_rgb);
  EXPECT_TRUE(std::equal(mesh.faces.begin(), mesh.faces.end(), read.faces.begin()));
  mesh.colours_rgb.pop_back();
  EXPECT_THROW(writePly(path, mesh), std::runtime_error);
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

}  // namespace
}  // namespace sift_hull
