// hull_node with free-space carving: a concave synthetic scene (the cup) carved by its silhouettes,
// then SurfacePoints messages of neighbouring pairs (exact points from the renderer's depth maps,
// seen by both views of their pair) arrive, and the octomap loses at least a fifth of the pocket a
// visual hull keeps, and none of the solid. Every wait has a deadline.

#include <geometry_msgs/TransformStamped.h>
#include <gtest/gtest.h>
#include <octomap/OcTree.h>
#include <ros/ros.h>
#include <rosgraph_msgs/Log.h>
#include <sensor_msgs/CameraInfo.h>
#include <sensor_msgs/Image.h>
#include <tf2_ros/static_transform_broadcaster.h>

#include <algorithm>
#include <cmath>
#include <functional>
#include <iostream>
#include <limits>
#include <memory>

#include "cup_scene.h"
#include "hull_node_fixture.h"
#include "lib/conversions.h"
#include "ros_wait.h"
#include "sift_hull/Octomap.h"
#include "sift_hull/SurfacePoints.h"
#include "sift_hull/synthetic/scene.h"
#include "sift_hull/synthetic/shape.h"

namespace sift_hull {
namespace {

namespace rc = ros_conversions;
using test::waitFor;

constexpr int kCupViews = 20;
/// Pairs per view: its nearest views. Points are those both views of a pair see, so that each
/// view's surface of points covers only what it shares with its partners (the pocket's far walls
/// from the upper views): more partners, more of the pocket (1: 10 %, 4: 27 %, 8: 28 % of it
/// carved at depth 7, the same points through the core).
constexpr int kPartners = 4;

using test::frameOf;

using test::occupiedFraction;

/// View v's depth-map points (every `step`-th pixel) that view w sees too, as w would.
sift_hull::SurfacePoints exactPairPoints(const RenderedView& v, const RenderedView& w, int step) {
  std::vector<SurfacePoint> points;
  for (int y = 0; y < v.depth.rows; y += step) {
    for (int x = 0; x < v.depth.cols; x += step) {
      const float d = v.depth.at<float>(y, x);
      if (!std::isfinite(d)) continue;
      const Eigen::Vector3d X = v.view.camera.backProject(Eigen::Vector2d(x, y), d);
      const Eigen::Vector2d px = w.view.camera.project(X);
      const int u = static_cast<int>(std::lround(px.x())),
                r = static_cast<int>(std::lround(px.y()));
      if (u < 0 || r < 0 || u >= w.depth.cols || r >= w.depth.rows) continue;
      const float seen = w.depth.at<float>(r, u);
      if (!(std::abs(seen - w.view.camera.depth(X)) < 0.01)) continue;  // hidden from w
      SurfacePoint point;
      point.X_W = X;
      points.push_back(point);
    }
  }
  std_msgs::Header header;
  header.frame_id = "world";
  header.stamp = ros::Time::now();
  return rc::surfacePointsMessage(header, v.view.camera, w.view.camera, points);
}

TEST(HullRefineTest, SurfacePointsCarveTheCupsPocketFromTheOctomapAndNothingOfTheCup) {
  ros::NodeHandle nh;
  const std::vector<RenderedView> views = renderScene(test::cupScene(kCupViews));
  tf2_ros::StaticTransformBroadcaster tf;
  test::sendCameraPoses(&tf, views, kCupViews);
  ros::Publisher silhouette_pub = nh.advertise<sensor_msgs::Image>("silhouette", 50);
  ros::Publisher info_pub = nh.advertise<sensor_msgs::CameraInfo>("camera_info", 50);
  ros::Publisher points_pub = nh.advertise<sift_hull::SurfacePoints>("surface_points", 50);
  sift_hull::OctomapConstPtr last;
  ros::Subscriber sub = nh.subscribe<sift_hull::Octomap>(
      "octomap_binary", 5, [&](const sift_hull::OctomapConstPtr& m) { last = m; });
  // The node's errors, from the start: connected before any message is sent.
  std::vector<std::string> errors;
  ros::Subscriber rosout =
      nh.subscribe<rosgraph_msgs::Log>("/rosout", 50, [&](const rosgraph_msgs::LogConstPtr& log) {
        if (log->level == rosgraph_msgs::Log::ERROR) errors.push_back(log->msg);
      });
  ASSERT_TRUE(waitFor([&] {
    return silhouette_pub.getNumSubscribers() > 0 && info_pub.getNumSubscribers() > 0 &&
           points_pub.getNumSubscribers() > 0 && rosout.getNumPublishers() > 0;
  })) << "the hull node did not subscribe";
  ros::Time stamp;
  for (int v = 0; v < kCupViews; ++v) {
    std_msgs::Header header;
    header.stamp = stamp = ros::Time::now();
    header.frame_id = frameOf(v);
    info_pub.publish(rc::cameraInfoMessage(views[v].view.camera, views[v].mask.size(), header));
    silhouette_pub.publish(rc::imageMessage(views[v].mask, header));
    ros::WallDuration(0.05).sleep();
  }
  ASSERT_TRUE(waitFor([&] { return last && last->header.stamp >= stamp; }, 60.0))
      << "no octomap of the silhouettes";
  const test::CupRegions regions;
  const test::Region &pocket = regions.pocket, &solid = regions.solid;
  const std::unique_ptr<octomap::OcTree> carved_by_silhouettes = rc::octreeFromMessage(*last);
  const double pocket_before = occupiedFraction(*carved_by_silhouettes, pocket);
  const double solid_before = occupiedFraction(*carved_by_silhouettes, solid);
  EXPECT_GT(pocket_before, 0.9) << "the silhouettes' hull should fill the pocket";
  EXPECT_GT(solid_before, 0.98);

  // Bad messages first: each refused with its reason on /rosout, and the node carries on.
  sift_hull::SurfacePoints unknown_frame = exactPairPoints(views[0], views[1], 16);
  unknown_frame.header.frame_id = "nowhere";
  sift_hull::SurfacePoints short_errors = exactPairPoints(views[0], views[1], 16);
  short_errors.reprojection_px.pop_back();
  sift_hull::SurfacePoints nan_point = exactPairPoints(views[0], views[1], 16);
  nan_point.points.front().x = std::nan("");
  for (const auto* bad : {&unknown_frame, &short_errors, &nan_point}) points_pub.publish(*bad);
  const auto logged = [&](const std::string& part) {
    return std::any_of(errors.begin(), errors.end(), [&](const std::string& e) {
      return e.find("surface points ignored") != std::string::npos &&
             e.find(part) != std::string::npos;
    });
  };
  EXPECT_TRUE(waitFor([&] {
    return logged("nowhere") && logged("reprojection errors") && logged("not a finite");
  })) << "no error for each bad SurfacePoints message";

  // Each view with its four nearest (camera centres), as a matcher on those pairs would give them.
  for (int v = 0; v < kCupViews; ++v) {
    std::vector<int> others;
    for (int w = 0; w < kCupViews; ++w) {
      if (w != v) others.push_back(w);
    }
    const Eigen::Vector3d centre = views[v].view.camera.centre();
    std::sort(others.begin(), others.end(), [&](int a, int b) {
      return (views[a].view.camera.centre() - centre).norm() <
             (views[b].view.camera.centre() - centre).norm();
    });
    for (int k = 0; k < kPartners; ++k) {
      points_pub.publish(exactPairPoints(views[v], views[others[k]], 4));
      ros::WallDuration(0.01).sleep();
    }
  }
  double pocket_after = pocket_before, solid_after = solid_before;
  const bool carved = waitFor(
      [&] {
        if (!last) return false;
        pocket_after = occupiedFraction(*rc::octreeFromMessage(*last), pocket);
        return pocket_after < 0.8 * pocket_before;
      },
      90.0);
  solid_after = occupiedFraction(*rc::octreeFromMessage(*last), solid);
  std::cout << "pocket occupied " << pocket_before << " -> " << pocket_after << ", cup "
            << solid_before << " -> " << solid_after << '\n';
  EXPECT_TRUE(carved) << "the pocket stays " << pocket_after << " occupied";
  EXPECT_GT(solid_after, solid_before - 0.005) << "the points carved the cup itself";
}

}  // namespace
}  // namespace sift_hull

int main(int argc, char** argv) {
  ::testing::InitGoogleTest(&argc, argv);
  ros::init(argc, argv, "test_hull_refine");
  ros::NodeHandle nh;
  return RUN_ALL_TESTS();
}
