// The hull node on raw distorted silhouettes: the sphere's masks rendered through a plumb_bob
// lens (k1 = -0.6), published as /raw/image_raw with the camera_info (D included) beside them, go
// to one hull node carving through the lens model and, rectified by Debian's image_proc, to a
// second with ~rectified. Each node's hull must be the hull of the same views rendered without
// distortion, within one voxel. Every wait has a deadline.

#include <geometry_msgs/TransformStamped.h>
#include <gtest/gtest.h>
#include <octomap/OcTree.h>
#include <ros/ros.h>
#include <sensor_msgs/CameraInfo.h>
#include <sensor_msgs/Image.h>
#include <tf2_ros/static_transform_broadcaster.h>

#include <algorithm>
#include <cmath>
#include <memory>
#include <sstream>
#include <string>
#include <vector>

#include "common/octomap_volume.h"
#include "hull_node_fixture.h"
#include "lib/conversions.h"
#include "ros_wait.h"
#include "sift_hull/Octomap.h"
#include "sift_hull/hull/hull_config.h"
#include "sift_hull/hull/hull_octomap.h"
#include "sift_hull/hull/hull_pipeline.h"
#include "sift_hull/synthetic/scene.h"

namespace sift_hull {
namespace {

using test::kViews;
using test::occupiedVolume;
using test::waitFor;

constexpr int kMaxDepth = 7;  // hull_distorted.test's ~max_depth

SceneConfig sceneConfig(const LensDistortion& distortion) {
  SceneConfig config = test::sphereSceneConfig();
  config.fill_fraction = 0.9;  // the outline far from the centre, where the lens bends most
  config.distortion = distortion;
  return config;
}

std::unique_ptr<octomap::OcTree> treeOf(const sift_hull::Octomap& message) {
  auto tree = std::make_unique<octomap::OcTree>(message.resolution);
  std::stringstream data(std::string(message.data.begin(), message.data.end()));
  tree->readBinaryData(data);
  return tree;
}

/// The hull of `views` built offline at kMaxDepth, as OctoMap's tree.
std::unique_ptr<octomap::OcTree> offlineTree(const HullInput& input) {
  HullConfig config;
  config.max_depth = kMaxDepth;
  return toOctomap(buildHull(input, config).hull);
}

double occupiedVolumeOf(const octomap::OcTree& tree) {
  double volume_m3 = 0.0;
  for (auto leaf = tree.begin_leafs(); leaf != tree.end_leafs(); ++leaf) {
    if (tree.isNodeOccupied(*leaf)) volume_m3 += std::pow(leaf.getSize(), 3);
  }
  return volume_m3;
}

bool occupiedAt(const octomap::OcTree& tree, const octomap::point3d& p) {
  const octomap::OcTreeNode* node = tree.search(p);
  return node && tree.isNodeOccupied(node);
}

/// The share of `a`'s occupied volume (in cells of a's resolution) with no occupied cell of `b`
/// within one of b's cells: 0 when `b` dilated by one cell contains `a`.
double uncoveredFraction(const octomap::OcTree& a, const octomap::OcTree& b) {
  const double r = a.getResolution(), step = b.getResolution();
  size_t cells = 0, uncovered = 0;
  for (auto leaf = a.begin_leafs(); leaf != a.end_leafs(); ++leaf) {
    if (!a.isNodeOccupied(*leaf)) continue;
    const int n = static_cast<int>(std::lround(leaf.getSize() / r));
    const octomap::point3d corner = leaf.getCoordinate() - octomap::point3d(1, 1, 1) * (n * r / 2);
    for (int i = 0; i < n * n * n; ++i) {
      const octomap::point3d c =
          corner + octomap::point3d(i % n + 0.5, i / n % n + 0.5, i / (n * n) + 0.5) * r;
      ++cells;
      bool covered = occupiedAt(b, c);
      for (int k = 0; k < 27 && !covered; ++k) {
        covered = occupiedAt(b, c + octomap::point3d(k % 3 - 1, k / 3 % 3 - 1, k / 9 - 1) * step);
      }
      uncovered += !covered;
    }
  }
  return cells == 0 ? 1.0 : static_cast<double>(uncovered) / cells;
}

class HullDistortedTest : public ::testing::Test {
 protected:
  void SetUp() override {
    views_ = renderScene(sceneConfig(kLens));
    std::vector<geometry_msgs::TransformStamped> poses;
    for (int v = 0; v < kViews; ++v) {
      poses.push_back(ros_conversions::cameraPoseMessage(views_[v].view.camera, "world",
                                                         "camera_" + std::to_string(v), {}));
    }
    tf_.sendTransform(poses);
    image_pub_ = nh_.advertise<sensor_msgs::Image>("/raw/image_raw", 20);
    info_pub_ = nh_.advertise<sensor_msgs::CameraInfo>("/raw/camera_info", 20);
    for (int n = 0; n < 2; ++n) {
      octomap_subs_[n] = nh_.subscribe<sift_hull::Octomap>(
          kNodes[n] + std::string("/octomap_binary"), 5,
          [this, n](const sift_hull::OctomapConstPtr& message) { octomaps_[n] = message; });
    }
    // The raw views have two subscribers, the hull node and image_proc (which subscribes once the
    // second hull node subscribes image_rect); camera_info has the second hull node too.
    ASSERT_TRUE(waitFor([&] {
      return image_pub_.getNumSubscribers() >= 2 && info_pub_.getNumSubscribers() >= 3;
    })) << "the hull nodes and image_proc did not connect";
  }

  ros::Time publishViews() {
    std_msgs::Header header;
    for (int v = 0; v < kViews; ++v) {
      header.stamp = ros::Time::now();
      header.frame_id = "camera_" + std::to_string(v);
      info_pub_.publish(
          ros_conversions::cameraInfoMessage(views_[v].view.camera, views_[v].mask.size(), header));
      image_pub_.publish(ros_conversions::imageMessage(views_[v].mask, header));
      ros::WallDuration(0.05).sleep();
    }
    return header.stamp;
  }

  static constexpr const char* kNodes[2] = {"/distorted", "/rectified"};
  const LensDistortion kLens{-0.6, 0.0, 0.0, 0.0, 0.0};
  ros::NodeHandle nh_;
  tf2_ros::StaticTransformBroadcaster tf_;
  ros::Publisher image_pub_, info_pub_;
  ros::Subscriber octomap_subs_[2];
  sift_hull::OctomapConstPtr octomaps_[2];
  std::vector<RenderedView> views_;
};

TEST_F(HullDistortedTest, BothNodesCarveTheHullOfTheUndistortedViews) {
  const ros::Time last = publishViews();
  for (int n = 0; n < 2; ++n) {
    ASSERT_TRUE(waitFor([&] { return octomaps_[n] && octomaps_[n]->header.stamp >= last; }))
        << "no octomap for the last view from " << kNodes[n];
  }
  // Ground truth: the same cameras without a lens, their masks rendered without distortion.
  const std::unique_ptr<octomap::OcTree> truth =
      offlineTree(hullInputOf(renderScene(sceneConfig({}))));
  const double truth_m3 = occupiedVolumeOf(*truth);
  // The lens matters here: the distorted masks taken as pinhole ones give a hull 5 % smaller or
  // more, beyond the tolerance below.
  HullInput pinhole = hullInputOf(views_);
  for (PinholeCamera& camera : pinhole.cameras) camera = camera.withDistortion({});
  ASSERT_LT(occupiedVolumeOf(*offlineTree(pinhole)), 0.95 * truth_m3);

  for (int n = 0; n < 2; ++n) {
    SCOPED_TRACE(kNodes[n]);
    EXPECT_EQ(octomaps_[n]->header.frame_id, "world");
    EXPECT_NEAR(occupiedVolume(*octomaps_[n]), truth_m3, 0.03 * truth_m3);
    const std::unique_ptr<octomap::OcTree> node = treeOf(*octomaps_[n]);
    EXPECT_NEAR(node->getResolution(), truth->getResolution(), 0.05 * truth->getResolution());
    EXPECT_LE(uncoveredFraction(*node, *truth), 0.002);
    EXPECT_LE(uncoveredFraction(*truth, *node), 0.002);
  }
}

}  // namespace
}  // namespace sift_hull

int main(int argc, char** argv) {
  ::testing::InitGoogleTest(&argc, argv);
  ros::init(argc, argv, "test_hull_distorted");
  ros::NodeHandle nh;  // keeps the node alive through the tests
  return RUN_ALL_TESTS();
}
