// The hull node wired up: synthetic silhouettes, camera_info and tf in; octomap and cloud out;
// ~reset; bad input answered with an error while later good input still counts. One behaviour per
// case, each from an empty hull (the fixture resets it); every wait has a deadline.

#include <geometry_msgs/TransformStamped.h>
#include <gtest/gtest.h>
#include <octomap/OcTree.h>
#include <ros/ros.h>
#include <rosgraph_msgs/Log.h>
#include <sensor_msgs/CameraInfo.h>
#include <sensor_msgs/Image.h>
#include <sensor_msgs/PointCloud2.h>
#include <std_srvs/Empty.h>
#include <tf2_eigen/tf2_eigen.h>
#include <tf2_ros/static_transform_broadcaster.h>

#include <algorithm>
#include <cmath>
#include <functional>
#include <iostream>
#include <mutex>
#include <sstream>

#include "common/octomap_volume.h"
#include "diagnostics_wait.h"
#include "hull_node_fixture.h"
#include "lib/conversions.h"
#include "ros_wait.h"
#include "sift_hull/Octomap.h"
#include "sift_hull/hull/hull_config.h"
#include "sift_hull/hull/hull_octomap.h"
#include "sift_hull/hull/hull_pipeline.h"
#include "sift_hull/hull/hull_view.h"
#include "sift_hull/synthetic/scene.h"

namespace sift_hull {
namespace {

using test::frameOf;
using test::HullNodeTest;
using test::kDeadline_s;
using test::kViews;
using test::occupiedVolume;
using test::waitFor;
namespace rc = ros_conversions;

/// The volume OctoMap gives the offline hull of the test's views at depth 6, and its resolution.
std::pair<double, double> offlineVolumeAndResolution(const std::vector<RenderedView>& views) {
  HullConfig config;
  config.max_depth = 6;
  const HullResult offline = buildHull(hullInputOf(views), config);
  return {occupiedVolume(rc::octomapMessage(*toOctomap(offline.hull), {})),
          offline.hull.cube().resolution_m};
}

const double kSphere_m3 = 4.0 / 3.0 * M_PI * std::pow(0.8, 3);

TEST_F(HullNodeTest, CarvesTheOfflineHullOfTheSameViews) {
  const ros::Time last = publishAllViews();
  ASSERT_TRUE(octomapStampedAtLeast(last)) << "no octomap for the last view";
  // The box refitted as views shrank it (within a cell of the LP box of all views).
  const auto [offline_m3, resolution_m] = offlineVolumeAndResolution(views_);
  EXPECT_NEAR(last_octomap_->resolution, resolution_m, 0.02 * resolution_m);
  EXPECT_EQ(last_octomap_->header.frame_id, "world");
  EXPECT_NEAR(occupiedVolume(*last_octomap_), offline_m3, 0.02 * offline_m3);
  EXPECT_NEAR(occupiedVolume(*last_octomap_), kSphere_m3, 0.3 * kSphere_m3);
}

TEST_F(HullNodeTest, PublishesTheOccupiedCellsWithTheMap) {
  const ros::Time last = publishAllViews();
  ASSERT_TRUE(waitFor([&] { return last_cloud_ && last_cloud_->header.stamp >= last; }))
      << "no occupied_cells for the last view";
  EXPECT_EQ(last_cloud_->header.frame_id, "world");
  EXPECT_GT(last_cloud_->width * last_cloud_->height, 100u);
}

TEST_F(HullNodeTest, ResetPublishesAnEmptyMapAndTheNextViewsCarveAnew) {
  ASSERT_TRUE(octomapStampedAtLeast(publishAllViews()));
  ASSERT_GT(occupiedVolume(*last_octomap_), 0.0);
  resetHull();
  ASSERT_TRUE(octomapStampedAtLeast(publishAllViews())) << "views after ~reset were not carved";
  const double offline_m3 = offlineVolumeAndResolution(views_).first;
  EXPECT_NEAR(occupiedVolume(*last_octomap_), offline_m3, 0.02 * offline_m3);
}

TEST_F(HullNodeTest, RefusesBadViewsAndCarvesTheGoodOnesAfterThem) {
  publishView(
      0, [](sensor_msgs::Image* image, sensor_msgs::CameraInfo*) { image->encoding = "rgb8"; });
  publishView(1, [](sensor_msgs::Image*, sensor_msgs::CameraInfo* info) { info->width = 640; });
  publishView(2, [](sensor_msgs::Image*, sensor_msgs::CameraInfo* info) { info->K.fill(0.0); });
  publishView(
      3, [](sensor_msgs::Image*, sensor_msgs::CameraInfo* info) { info->K[0] = std::nan(""); });
  publishView(4, [](sensor_msgs::Image* image, sensor_msgs::CameraInfo*) { image->data.clear(); });
  publishView(5, [](sensor_msgs::Image* image, sensor_msgs::CameraInfo* info) {
    image->header.frame_id = info->header.frame_id = "camera_without_pose";
  });
  publishView(6, [](sensor_msgs::Image* image, sensor_msgs::CameraInfo* info) {
    image->header.frame_id = info->header.frame_id = "camera_nan";
  });
  // Each refused with its own error (and so counted in no hull).
  for (int v = 0; v < 5; ++v) {
    EXPECT_TRUE(loggedError({"view '" + frameOf(v) + "' ignored"})) << "view " << v;
  }
  EXPECT_TRUE(loggedError({"no pose of 'camera_without_pose'"}));
  EXPECT_TRUE(loggedError({"no pose of 'camera_nan'"}));
  ASSERT_TRUE(octomapStampedAtLeast(publishAllViews())) << "good views after bad ones not carved";
  const double offline_m3 = offlineVolumeAndResolution(views_).first;
  EXPECT_NEAR(occupiedVolume(*last_octomap_), offline_m3, 0.02 * offline_m3)
      << "a bad view changed the hull";
}

TEST_F(HullNodeTest, CarvesViewsThatArriveNewestFirst) {
  const ros::Time now = ros::Time::now();
  for (int v = 0; v < kViews; ++v) publishView(v, {}, now - ros::Duration(0.1 * v));
  ASSERT_TRUE(waitFor([&] { return occupiedVolume(*last_octomap_) > 0.5 * kSphere_m3; }))
      << "views out of order were not carved";
  ros::WallDuration(1.0).sleep();  // every view carved by then
  ros::spinOnce();
  const double offline_m3 = offlineVolumeAndResolution(views_).first;
  EXPECT_NEAR(occupiedVolume(*last_octomap_), offline_m3, 0.02 * offline_m3);
}

/// The camera of view 0 turned by 40 degrees about the world's z axis through the origin: a
/// viewpoint none of the views has.
PinholeCamera turnedCamera(const PinholeCamera& camera) {
  const Eigen::Matrix3d turn =
      Eigen::AngleAxisd(40.0 * M_PI / 180.0, Eigen::Vector3d::UnitZ()).toRotationMatrix();
  return PinholeCamera::fromCentre(camera.K(), camera.R() * turn.transpose(),
                                   turn * camera.centre());
}

TEST_F(HullNodeTest, ASilhouetteWhosePoseComesAfterTheTimeoutIsReportedAndNotCarved) {
  ASSERT_TRUE(octomapStampedAtLeast(publishAllViews()));
  // The node's count of views dropped without pose before this one (other cases' frames without
  // pose may be among them).
  const auto withoutPose = [&](double at_least) {
    return test::diagnosticValue(nh_, "hull", "views without pose",
                                 [at_least](double n) { return n >= at_least; });
  };
  const double before = withoutPose(0.0);
  ASSERT_FALSE(std::isnan(before)) << "no 'views without pose' in the node's /diagnostics";
  const ros::Time late =
      publishView(0, [](sensor_msgs::Image* image, sensor_msgs::CameraInfo* info) {
        image->header.frame_id = info->header.frame_id = "camera_late";
      });
  // hull_node.test sets ~pose_timeout_s to 1 s.
  ASSERT_TRUE(loggedError({"no pose of 'camera_late'", "pose_timeout_s"}))
      << "no error for a pose that did not come in time";
  EXPECT_EQ(withoutPose(before + 1.0), before + 1.0)
      << "the dropped view is not counted in /diagnostics";
  const PinholeCamera camera = turnedCamera(views_[0].view.camera);
  tf_.sendTransform(ros_conversions::cameraPoseMessage(camera, "world", "camera_late", {}));
  ros::WallDuration(2.0).sleep();  // the pose is in tf now: the view would be carved by then
  ros::spinOnce();
  EXPECT_LT(last_octomap_->header.stamp, late) << "a view whose pose came too late was carved";
  EXPECT_EQ(withoutPose(0.0), before + 1.0) << "the late pose counted its view a second time";
  // The same viewpoint in time is carved.
  const ros::Time timely =
      publishView(0, [](sensor_msgs::Image* image, sensor_msgs::CameraInfo* info) {
        image->header.frame_id = info->header.frame_id = "camera_late";
      });
  EXPECT_TRUE(octomapStampedAtLeast(timely)) << "a view with its pose in time was not carved";
}

TEST_F(HullNodeTest, WarnsWhenSilhouettesAndCameraInfoArriveButDoNotPair) {
  publishView(1);  // a pair: what arrived before is accounted for
  // A segmentation node that re-stamps its masks: the camera_info is 5 ms off.
  const std::string warning = test::warningOf(nh_, "hull", "have not paired", [&] {
    publishView(2, [](sensor_msgs::Image*, sensor_msgs::CameraInfo* info) {
      info->header.stamp += ros::Duration(0.005);
    });
  });
  ASSERT_FALSE(warning.empty()) << "no WARN on /diagnostics within 20 s";
  EXPECT_NE(warning.find("silhouette ("), std::string::npos) << warning;
  EXPECT_NE(warning.find("camera_info ("), std::string::npos) << warning;
  EXPECT_NE(warning.find("equal stamp"), std::string::npos) << warning;
}

class HullFromImageTest : public HullNodeTest {
 protected:
  bool fromImage() const override { return true; }
};

TEST_F(HullFromImageTest, ExtractsSilhouettesFromImagesAndCarves) {
  ASSERT_TRUE(octomapStampedAtLeast(publishAllViews())) << "no octomap for the last view";
  // The default silhouette method on the rendered images gives close to the rendered masks' hull.
  EXPECT_NEAR(occupiedVolume(*last_octomap_), kSphere_m3, 0.3 * kSphere_m3);
}

/// A cup on a tiled floor with its shadow, on a textured background: one image alone cannot
/// tell the object from the floor; the default method (auto) segments the views together as they
/// come and carves the hull again from their silhouettes.
class HullFromImageOnAFloorTest : public HullNodeTest {
 protected:
  bool fromImage() const override { return true; }
  SceneConfig sceneConfig() const override {
    SceneConfig config = test::sphereSceneConfig();
    config.shape = "cup";
    config.views = 12;
    config.background = "textured";
    config.support = "floor";
    return config;
  }
};

/// The IoU of two maps' occupied space, sampled on a grid of 64^3 points over the first's box.
double occupiedIou(const octomap::OcTree& a, const octomap::OcTree& b) {
  double x0, y0, z0, x1, y1, z1;
  a.getMetricMin(x0, y0, z0);
  a.getMetricMax(x1, y1, z1);
  const auto occupied = [](const octomap::OcTree& tree, const octomap::point3d& p) {
    const octomap::OcTreeNode* node = tree.search(p);
    return node != nullptr && tree.isNodeOccupied(node);
  };
  double both = 0.0, either = 0.0;
  constexpr int kSteps = 64;
  for (int i = 0; i < kSteps; ++i) {
    for (int j = 0; j < kSteps; ++j) {
      for (int k = 0; k < kSteps; ++k) {
        const octomap::point3d p(x0 + (x1 - x0) * (i + 0.5) / kSteps,
                                 y0 + (y1 - y0) * (j + 0.5) / kSteps,
                                 z0 + (z1 - z0) * (k + 0.5) / kSteps);
        const bool in_a = occupied(a, p), in_b = occupied(b, p);
        both += in_a && in_b;
        either += in_a || in_b;
      }
    }
  }
  return either > 0.0 ? both / either : 0.0;
}

TEST_F(HullFromImageOnAFloorTest, SegmentsTheViewsTogetherAndCarvesTheObjectAlone) {
  // The hull of the exact masks at the node's depth.
  HullConfig config;
  config.max_depth = 6;
  const std::unique_ptr<octomap::OcTree> exact =
      toOctomap(buildHull(hullInputOf(views_), config).hull);
  const ros::Time last = publishAllViews();
  ASSERT_TRUE(octomapStampedAtLeast(last)) << "no octomap for the last view";
  // Each view's own silhouette holds floor and shadow; once the views are segmented together
  // (at 4, 6 and 9 views, then when the queue has drained) the hull is the object's.
  double iou = 0.0;
  const bool near = waitFor(
      [&] {
        iou = last_octomap_ ? occupiedIou(*exact, *rc::octreeFromMessage(*last_octomap_)) : 0.0;
        return iou > 0.95;  // measured 0.980; each view on its own: 0.899
      },
      60.0);
  std::cout << "on a floor: the map's IoU with the exact masks' hull " << iou << '\n';
  EXPECT_TRUE(near) << "the map's IoU with the exact masks' hull " << iou;
  EXPECT_EQ(last_octomap_->header.stamp, last) << "stamped with the newest view";
}

/// A stream faster than the node carves at depth 8: 300 views from 300 viewpoints at 100 Hz,
/// `~queue_size` large enough to hold them all (hull_sustained.test), so the queue does not drain
/// until the stream ends. The map must still be published while the views come (at least every
/// second, kMaxPublishDelay_s), and once they are all carved it is the offline hull of all of them.
TEST(HullSustainedTest, PublishesWhileAFasterStreamLastsAndEndsWithTheHullOfAllViews) {
  ros::NodeHandle nh;
  SceneConfig scene = test::sphereSceneConfig();
  scene.views = 300;
  const std::vector<RenderedView> views = renderScene(scene);
  tf2_ros::StaticTransformBroadcaster tf;
  std::vector<geometry_msgs::TransformStamped> poses;
  for (size_t v = 0; v < views.size(); ++v) {
    poses.push_back(ros_conversions::cameraPoseMessage(views[v].view.camera, "world",
                                                       frameOf(static_cast<int>(v)), {}));
  }
  tf.sendTransform(poses);
  ros::Publisher silhouette_pub = nh.advertise<sensor_msgs::Image>("silhouette", 400);
  ros::Publisher info_pub = nh.advertise<sensor_msgs::CameraInfo>("camera_info", 400);
  std::vector<std::pair<ros::WallTime, sift_hull::OctomapConstPtr>> maps;
  ros::Subscriber sub = nh.subscribe<sift_hull::Octomap>(
      "octomap_binary", 400,
      [&](const sift_hull::OctomapConstPtr& m) { maps.emplace_back(ros::WallTime::now(), m); });
  ASSERT_TRUE(waitFor([&] {
    return silhouette_pub.getNumSubscribers() > 0 && info_pub.getNumSubscribers() > 0 &&
           sub.getNumPublishers() > 0;
  }));
  ros::WallDuration(0.5).sleep();
  ros::spinOnce();
  maps.clear();  // the empty latched map
  const ros::WallTime start = ros::WallTime::now();
  ros::Time last;
  for (size_t v = 0; v < views.size(); ++v) {
    std_msgs::Header header;
    header.stamp = last = ros::Time::now();
    header.frame_id = frameOf(static_cast<int>(v));
    info_pub.publish(
        ros_conversions::cameraInfoMessage(views[v].view.camera, views[v].mask.size(), header));
    silhouette_pub.publish(ros_conversions::imageMessage(views[v].mask, header));
    ros::spinOnce();
    sleepUntilWall(start + ros::WallDuration(0.01 * (v + 1)));
  }
  const ros::WallTime end = ros::WallTime::now();
  const size_t during = maps.size();
  ASSERT_TRUE(
      waitFor([&] { return !maps.empty() && maps.back().second->header.stamp == last; }, 120.0))
      << "the last view's map did not come";
  std::cout << "sustained: " << views.size() << " views in " << (end - start).toSec() << " s, "
            << during << " maps while they came, " << maps.size() << " in all\n";
  // While the views came (3 s): the first view's map, then at least one a second later.
  EXPECT_GE(during, 2u) << "published " << during << " times in " << (end - start).toSec() << " s";
  EXPECT_LT(during, views.size() / 2) << "the queue drained: the stream did not outpace carving";
  HullConfig config;
  config.max_depth = 8;
  const HullResult offline = buildHull(hullInputOf(views), config);
  const sift_hull::Octomap& final_map = *maps.back().second;
  EXPECT_NEAR(final_map.resolution, offline.hull.cube().resolution_m,
              0.02 * offline.hull.cube().resolution_m);
  const double offline_m3 = occupiedVolume(rc::octomapMessage(*toOctomap(offline.hull), {}));
  EXPECT_NEAR(occupiedVolume(final_map), offline_m3, 0.02 * offline_m3);
}

}  // namespace
}  // namespace sift_hull

int main(int argc, char** argv) {
  ::testing::InitGoogleTest(&argc, argv);
  ros::init(argc, argv, "test_hull_node");
  ros::NodeHandle nh;  // keeps the node alive through the tests
  return RUN_ALL_TESTS();
}
