// The hull node's octomap_server interface: the octomap_binary and octomap_full services read back
// with OctoMap's own readers agree with the published topic, carved space is free and the object
// occupied, ~clear_bbx frees its box (and refuses bad boxes), octomap_full, the centres cloud and
// the free markers carry the same map, and Debian's octomap-tools read the map the service gives.
// Every wait has a deadline.

#include <gtest/gtest.h>
#include <octomap/AbstractOcTree.h>
#include <octomap/OcTree.h>
#include <ros/ros.h>
#include <sensor_msgs/PointCloud2.h>
#include <std_srvs/Empty.h>
#include <tf2_ros/buffer.h>
#include <tf2_ros/transform_listener.h>
#include <visualization_msgs/MarkerArray.h>

#include <cmath>
#include <memory>
#include <sstream>
#include <string>

#include "common/test_data.h"
#include "diagnostics_wait.h"
#include "hull_node_fixture.h"
#include "ros_wait.h"
#include "sift_hull/BoundingBoxQuery.h"
#include "sift_hull/GetOctomap.h"

namespace sift_hull {
namespace {

using test::HullNodeTest;
using test::kDeadline_s;
using test::kViews;
using test::waitFor;

/// The service's map read as octomap_msgs::msgToMap reads it: a tree of the message's id and
/// resolution, filled by readBinaryData (binary) or readData (full).
std::unique_ptr<octomap::OcTree> readMap(const sift_hull::Octomap& map) {
  std::unique_ptr<octomap::AbstractOcTree> tree(
      octomap::AbstractOcTree::createTree(map.id, map.resolution));
  auto* octree = dynamic_cast<octomap::OcTree*>(tree.get());
  if (octree == nullptr) return nullptr;
  tree.release();
  std::stringstream data;
  data.write(reinterpret_cast<const char*>(map.data.data()), map.data.size());
  if (map.binary) {
    octree->readBinaryData(data);
  } else {
    octree->readData(data);
  }
  return std::unique_ptr<octomap::OcTree>(octree);
}

/// The map a GetOctomap service gives (null when the call fails).
std::unique_ptr<octomap::OcTree> callMap(const std::string& service, sift_hull::Octomap* map) {
  sift_hull::GetOctomap call;
  if (!ros::service::call(service, call)) return nullptr;
  *map = call.response.map;
  return readMap(call.response.map);
}

/// 1 occupied, 0 free, -1 unknown.
int stateAt(const octomap::OcTree& tree, double x, double y, double z) {
  const octomap::OcTreeNode* node = tree.search(x, y, z);
  return node == nullptr ? -1 : tree.isNodeOccupied(node);
}

/// The number of leaves of `a` whose centre `b` does not give the same state.
size_t disagreements(const octomap::OcTree& a, const octomap::OcTree& b) {
  size_t differ = 0;
  for (auto leaf = a.begin_leafs(); leaf != a.end_leafs(); ++leaf) {
    differ += stateAt(b, leaf.getX(), leaf.getY(), leaf.getZ()) != a.isNodeOccupied(*leaf);
  }
  return differ;
}

sift_hull::BoundingBoxQuery boxQuery(double min, double max) {
  sift_hull::BoundingBoxQuery query;
  query.request.min.x = query.request.min.y = query.request.min.z = min;
  query.request.max.x = query.request.max.y = query.request.max.z = max;
  return query;
}

class HullOctomapTest : public HullNodeTest {
 protected:
  /// ~reset (the node may have the views already), then the sphere's views carved.
  void carveSphere() {
    std_srvs::Empty reset;
    ASSERT_TRUE(ros::service::waitForService("/hull/reset", ros::Duration(kDeadline_s)));
    ASSERT_TRUE(ros::service::call("/hull/reset", reset));
    ros::Time last;
    for (int v = 0; v < kViews; ++v) last = publishView(v);
    ASSERT_TRUE(octomapStampedAtLeast(last)) << "no octomap for the last view";
    for (const char* service : {"/octomap_binary", "/octomap_full", "/hull/clear_bbx"}) {
      ASSERT_TRUE(ros::service::waitForService(service, ros::Duration(kDeadline_s))) << service;
    }
  }
};

TEST_F(HullOctomapTest, ServicesGiveThePublishedMapWithFreeSpaceAndOctomapToolsReadIt) {
  ASSERT_NO_FATAL_FAILURE(carveSphere());
  sift_hull::Octomap binary_map, full_map;
  const std::unique_ptr<octomap::OcTree> binary = callMap("/octomap_binary", &binary_map);
  const std::unique_ptr<octomap::OcTree> full = callMap("/octomap_full", &full_map);
  ASSERT_TRUE(binary && full) << "a GetOctomap service failed or gave no OcTree";
  EXPECT_TRUE(binary_map.binary && !full_map.binary && full_map.id == "OcTree");
  EXPECT_EQ(binary_map.data, last_octomap_->data);  // the map as published
  EXPECT_EQ(binary_map.header.stamp, last_octomap_->header.stamp);
  EXPECT_EQ(binary_map.header.frame_id, "world");
  EXPECT_EQ(binary->getNumLeafNodes(), full->getNumLeafNodes());
  EXPECT_EQ(disagreements(*full, *binary), 0u);
  // The full map holds occupancies: the clamping values, occupied and free.
  for (auto leaf = full->begin_leafs(); leaf != full->end_leafs(); ++leaf) {
    const float expected = full->isNodeOccupied(*leaf) ? full->getClampingThresMaxLog()
                                                       : full->getClampingThresMinLog();
    ASSERT_FLOAT_EQ(leaf->getLogOdds(), expected);
  }
  // The sphere (radius 0.8 m at the origin) occupied, the cube's corner carved, beyond it unknown.
  double x, y, z;
  binary->getMetricMin(x, y, z);
  const double res = binary->getResolution();
  ASSERT_GT(std::hypot(x, y, z), 1.2);
  EXPECT_EQ(stateAt(*binary, 0.0, 0.0, 0.0), 1);
  EXPECT_EQ(stateAt(*binary, x + 1.5 * res, y + 1.5 * res, z + 1.5 * res), 0);
  EXPECT_EQ(stateAt(*binary, x - 0.5 * res, y - 0.5 * res, z - 0.5 * res), -1);

  // octomap_saver's files: the binary map as .bt, the full one as .ot, read by octomap-tools.
  const std::string dir = test::temporaryDirectory();
  ASSERT_TRUE(binary->writeBinary(dir + "/hull.bt"));
  ASSERT_TRUE(full->write(dir + "/hull_full.ot"));
  std::string out, err;
  ASSERT_EQ(test::runCommand("convert_octree " + dir + "/hull.bt " + dir + "/hull.ot", &out, &err),
            0)
      << out << err;
  ASSERT_EQ(
      test::runCommand("compare_octrees " + dir + "/hull_full.ot " + dir + "/hull.ot", &out, &err),
      0)
      << out << err;
  EXPECT_NE(out.find("KLD: 0\n"), std::string::npos) << out;  // the maps agree
}

/// Leaves of the tree: occupied ones, and the free volume (cubic metres).
struct LeafCount {
  size_t occupied = 0;
  double free_m3 = 0.0;
};
LeafCount countLeaves(const octomap::OcTree& tree) {
  LeafCount count;
  for (auto leaf = tree.begin_leafs(); leaf != tree.end_leafs(); ++leaf) {
    if (tree.isNodeOccupied(*leaf)) {
      ++count.occupied;
    } else {
      count.free_m3 += std::pow(leaf.getSize(), 3);
    }
  }
  return count;
}

TEST_F(HullOctomapTest, TheOtherTopicsCarryTheSameMap) {
  ASSERT_NO_FATAL_FAILURE(carveSphere());
  sift_hull::OctomapConstPtr full;
  sensor_msgs::PointCloud2ConstPtr centres;
  visualization_msgs::MarkerArrayConstPtr free;
  // Subscribed now: octomap_full and the free markers are built for a new subscriber at once.
  ros::Subscriber full_sub = nh_.subscribe<sift_hull::Octomap>(
      "octomap_full", 2, [&](const sift_hull::OctomapConstPtr& m) { full = m; });
  ros::Subscriber centres_sub = nh_.subscribe<sensor_msgs::PointCloud2>(
      "octomap_point_cloud_centers", 2,
      [&](const sensor_msgs::PointCloud2ConstPtr& m) { centres = m; });
  ros::Subscriber free_sub = nh_.subscribe<visualization_msgs::MarkerArray>(
      "free_cells_vis_array", 2,
      [&](const visualization_msgs::MarkerArrayConstPtr& m) { free = m; });
  const ros::Time stamp = last_octomap_->header.stamp;
  ASSERT_TRUE(waitFor([&] {
    return full && full->header.stamp == stamp && centres && centres->header.stamp == stamp &&
           free && !free->markers.empty() && free->markers[0].header.stamp == stamp;
  })) << "octomap_full, octomap_point_cloud_centers or free_cells_vis_array missing";
  sift_hull::Octomap served;
  ASSERT_NE(callMap("/octomap_full", &served), nullptr);
  EXPECT_EQ(full->data, served.data);
  EXPECT_FALSE(full->binary);
  const LeafCount leaves = countLeaves(*readMap(*last_octomap_));
  EXPECT_GT(leaves.occupied, 100u);
  EXPECT_EQ(static_cast<size_t>(centres->width) * centres->height, leaves.occupied);
  double free_m3 = 0.0;
  for (const visualization_msgs::Marker& m : free->markers) {
    EXPECT_EQ(m.ns, "free_cells");
    free_m3 += m.points.size() * std::pow(m.scale.x, 3);
  }
  EXPECT_GT(leaves.free_m3, 1.0);  // the cube's edge is about 1.7 m, the sphere's volume 2.1 m^3
  EXPECT_NEAR(free_m3, leaves.free_m3, 1e-6 * leaves.free_m3);
}

TEST_F(HullOctomapTest, ClearBbxFreesTheBoxUntilResetAndRefusesBadBoxes) {
  ASSERT_NO_FATAL_FAILURE(carveSphere());
  const ros::Time before = last_octomap_->header.stamp;
  sift_hull::BoundingBoxQuery clear = boxQuery(-0.2, 0.2);
  ASSERT_TRUE(ros::service::call("/hull/clear_bbx", clear));
  ASSERT_TRUE(waitFor([&] { return last_octomap_->header.stamp > before; }))
      << "~clear_bbx did not republish";
  const std::unique_ptr<octomap::OcTree> cleared = readMap(*last_octomap_);
  ASSERT_NE(cleared, nullptr);
  EXPECT_EQ(stateAt(*cleared, 0.0, 0.0, 0.0), 0);
  EXPECT_EQ(stateAt(*cleared, 0.19, -0.19, 0.19), 0);
  EXPECT_EQ(stateAt(*cleared, 0.0, 0.0, 0.5), 1);  // the sphere outside the box stays
  sift_hull::Octomap map;
  const std::unique_ptr<octomap::OcTree> served = callMap("/octomap_binary", &map);
  ASSERT_NE(served, nullptr);
  EXPECT_EQ(stateAt(*served, 0.0, 0.0, 0.0), 0);
  // min > max and NaN are refused (the call fails), and the map stays.
  sift_hull::BoundingBoxQuery inverted = boxQuery(0.3, -0.3), nan = boxQuery(-0.5, 0.5);
  nan.request.max.y = std::nan("");
  EXPECT_FALSE(ros::service::call("/hull/clear_bbx", inverted));
  EXPECT_FALSE(ros::service::call("/hull/clear_bbx", nan));
  EXPECT_EQ(stateAt(*callMap("/octomap_binary", &map), 0.0, 0.0, 0.5), 1);
  // A later view (a viewpoint none has: view 0 turned about the sphere's axis) republishes the
  // hull from the views, the box still cleared; after ~reset the box is forgotten.
  const Eigen::Matrix3d turn =
      Eigen::AngleAxisd(40.0 * M_PI / 180.0, Eigen::Vector3d::UnitZ()).toRotationMatrix();
  const PinholeCamera& camera = views_[0].view.camera;
  tf_.sendTransform(ros_conversions::cameraPoseMessage(
      PinholeCamera::fromCentre(camera.K(), camera.R() * turn.transpose(), turn * camera.centre()),
      "world", "camera_turned", {}));
  // The view only once tf here has the new frame: the node drops a view whose pose has not come
  // within ~pose_timeout_s, and under load the static transform can come later than the view.
  tf2_ros::Buffer buffer;
  tf2_ros::TransformListener listener(buffer);
  ASSERT_TRUE(waitFor([&] { return buffer.canTransform("world", "camera_turned", ros::Time(0)); }))
      << "the turned camera's pose did not reach tf";
  const ros::Time turned =
      publishView(0, [](sensor_msgs::Image* image, sensor_msgs::CameraInfo* info) {
        image->header.frame_id = info->header.frame_id = "camera_turned";
      });
  ASSERT_TRUE(octomapStampedAtLeast(turned))
      << "the turned view was not carved; the node's /diagnostics count "
      << test::diagnosticValue(nh_, "hull", "views without pose", [](double) { return true; }, 5.0)
      << " views without pose (dropped after ~pose_timeout_s)";
  EXPECT_EQ(stateAt(*readMap(*last_octomap_), 0.0, 0.0, 0.0), 0);
  EXPECT_EQ(stateAt(*readMap(*last_octomap_), 0.0, 0.0, 0.5), 1);
  ASSERT_NO_FATAL_FAILURE(carveSphere());  // ~reset, then the views again
  EXPECT_EQ(stateAt(*readMap(*last_octomap_), 0.0, 0.0, 0.0), 1);
}

}  // namespace
}  // namespace sift_hull

int main(int argc, char** argv) {
  ::testing::InitGoogleTest(&argc, argv);
  ros::init(argc, argv, "test_hull_octomap");
  ros::NodeHandle nh;  // keeps the node alive through the tests
  return RUN_ALL_TESTS();
}
