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
#include "sift_hull/eval/mesh_render.h"
#include "sift_hull/hull/mesh.h"

namespace sift_hull {
namespace {

using namespace test;

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

TEST(RasteriseTest, HalfTheFacesOfAClosedMeshDrawItsProjection) {
  // Every ray through a closed mesh's projection crosses it both ways: the faces that turn one way
  // in the image cover what all of them cover.
  const TriangleMesh mesh = sphereMesh();
  ASSERT_TRUE(checkMesh(mesh).watertight);
  const PinholeCamera camera = sphereCamera();
  const cv::Size size(320, 240);
  for (const PinholeCamera& seen_by : {camera, camera.reduced(2)}) {
    const cv::Mat all = rasteriseMask(mesh, seen_by, size);
    const cv::Mat half = rasteriseMask(mesh, seen_by, size, true);
    ASSERT_GT(cv::countNonZero(all), 1000);
    // Pixel centres exactly on the outline may go either way; none here.
    EXPECT_EQ(cv::countNonZero(all != half), 0);
  }
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
