// The OctoMap conversions of octomap_server's interface without a ROS master: the full map's round
// trip with its occupancies, reading messages back (and refusing bad ones), the free cells'
// markers, the coloured full map (ColorOcTree) and centres' cloud (PCL's rgb), the clear box's
// corners, and the services' md5sums, which must be octomap_msgs'.

#include <gtest/gtest.h>
#include <octomap/ColorOcTree.h>
#include <octomap/OcTree.h>
#include <pcl/point_cloud.h>
#include <pcl/point_types.h>
#include <pcl_conversions/pcl_conversions.h>

#include <sstream>

#include <cmath>
#include <memory>
#include <string>

#include "common/test_data.h"
#include "lib/conversions.h"
#include "sift_hull/BoundingBoxQuery.h"
#include "sift_hull/GetOctomap.h"
#include "sift_hull/hull/hull_octomap.h"
#include "sift_hull/hull/hull_pipeline.h"

namespace sift_hull {
namespace {

namespace rc = ros_conversions;

constexpr double kRes = 0.1;

std_msgs::Header mapHeader() {
  std_msgs::Header header;
  header.frame_id = "map";
  header.stamp = ros::Time(12, 345);
  return header;
}

/// Free voxels on the x axis, occupied ones on y, and one voxel updated once (an occupancy between
/// the clamping values, which only the full map keeps).
struct MixedTree {
  octomap::OcTree tree{kRes};
  MixedTree() {
    for (int i = 1; i <= 6; ++i) {
      tree.setNodeValue(i * kRes + 0.05, 0.05, 0.05, tree.getClampingThresMinLog());
      tree.setNodeValue(0.05, i * kRes + 0.05, 0.05, tree.getClampingThresMaxLog());
    }
    tree.updateNode(-0.55, -0.55, -0.55, true);  // log-odds 0.85, below the maximum 3.5
  }
};

TEST(OctomapFullMessage, RoundTripKeepsEveryLeafAndItsOccupancy) {
  const MixedTree mixed;
  const sift_hull::Octomap message = rc::octomapFullMessage(mixed.tree, mapHeader());
  EXPECT_FALSE(message.binary);
  EXPECT_EQ(message.id, "OcTree");
  EXPECT_EQ(message.resolution, kRes);
  EXPECT_EQ(message.header.frame_id, "map");
  EXPECT_EQ(message.header.stamp, ros::Time(12, 345));
  const std::unique_ptr<octomap::OcTree> read = rc::octreeFromMessage(message);
  ASSERT_EQ(read->getNumLeafNodes(), mixed.tree.getNumLeafNodes());
  for (auto leaf = mixed.tree.begin_leafs(); leaf != mixed.tree.end_leafs(); ++leaf) {
    const octomap::OcTreeNode* node = read->search(leaf.getKey(), leaf.getDepth());
    ASSERT_NE(node, nullptr);
    EXPECT_FLOAT_EQ(node->getLogOdds(), leaf->getLogOdds());
  }
  EXPECT_NEAR(read->search(-0.55, -0.55, -0.55)->getLogOdds(), 0.847298, 1e-5);
  // The binary map keeps occupied / free only: the once-updated voxel at the clamping maximum.
  const std::unique_ptr<octomap::OcTree> binary =
      rc::octreeFromMessage(rc::octomapMessage(mixed.tree, mapHeader()));
  EXPECT_EQ(binary->getNumLeafNodes(), mixed.tree.getNumLeafNodes());
  EXPECT_FLOAT_EQ(binary->search(-0.55, -0.55, -0.55)->getLogOdds(),
                  binary->getClampingThresMaxLog());
  EXPECT_FALSE(binary->isNodeOccupied(binary->search(0.35, 0.05, 0.05)));
  EXPECT_TRUE(binary->isNodeOccupied(binary->search(0.05, 0.35, 0.05)));
  // An empty tree writes no data and reads back empty.
  const sift_hull::Octomap empty = rc::octomapFullMessage(octomap::OcTree(0.2), mapHeader());
  EXPECT_TRUE(empty.data.empty());
  EXPECT_EQ(rc::octreeFromMessage(empty)->getNumLeafNodes(), 0u);
}

TEST(OctomapFullMessage, OfAColorOcTreeKeepsItsColoursForOctomapsReader) {
  octomap::ColorOcTree tree(kRes);
  tree.updateNode(0.05, 0.05, 0.05, true)->setColor(200, 30, 10);
  tree.updateNode(1.05, 0.05, 0.05, true)->setColor(5, 6, 250);
  tree.updateNode(0.05, 1.05, 0.05, false);
  const sift_hull::Octomap message = rc::octomapFullMessage(tree, mapHeader());
  EXPECT_EQ(message.id, "ColorOcTree");  // what octomap_msgs::msgToMap makes a ColorOcTree of
  EXPECT_FALSE(message.binary);
  EXPECT_EQ(message.resolution, kRes);
  EXPECT_EQ(message.header.frame_id, "map");
  octomap::ColorOcTree back(message.resolution);
  std::stringstream data(std::string(message.data.begin(), message.data.end()));
  back.readData(data);
  const octomap::ColorOcTreeNode* red = back.search(0.05, 0.05, 0.05);
  const octomap::ColorOcTreeNode* blue = back.search(1.05, 0.05, 0.05);
  const octomap::ColorOcTreeNode* free = back.search(0.05, 1.05, 0.05);
  ASSERT_TRUE(red && blue && free);
  EXPECT_EQ(red->getColor(), octomap::ColorOcTreeNode::Color(200, 30, 10));
  EXPECT_EQ(blue->getColor(), octomap::ColorOcTreeNode::Color(5, 6, 250));
  EXPECT_TRUE(back.isNodeOccupied(red));
  EXPECT_FALSE(back.isNodeOccupied(free));
}

TEST(PointCloudMessage, WithColoursIsPclsXyzrgbAndRefusesOtherCounts) {
  const std::vector<Eigen::Vector3d> points = {{1.0, 2.0, 3.0}, {-1.0, 0.5, 0.25}};
  const sensor_msgs::PointCloud2 message =
      rc::pointCloudMessage(points, {{255, 0, 10}, {1, 128, 254}}, mapHeader());
  EXPECT_EQ(message.header.frame_id, "map");
  std::vector<std::string> fields;
  for (const sensor_msgs::PointField& field : message.fields) fields.push_back(field.name);
  EXPECT_EQ(fields, (std::vector<std::string>{"x", "y", "z", "rgb"}));
  pcl::PointCloud<pcl::PointXYZRGB> cloud;
  pcl::fromROSMsg(message, cloud);
  ASSERT_EQ(cloud.size(), 2u);
  EXPECT_FLOAT_EQ(cloud[1].x, -1.0f);
  EXPECT_FLOAT_EQ(cloud[1].z, 0.25f);
  EXPECT_EQ(cloud[0].r, 255);
  EXPECT_EQ(cloud[0].b, 10);
  EXPECT_EQ(cloud[1].g, 128);
  EXPECT_EQ(cloud[1].rgba & 0xFFFFFFu, 0x0180FEu);  // rviz's RGB8: 0x00RRGGBB
  EXPECT_THROW(rc::pointCloudMessage(points, {{1, 2, 3}}, mapHeader()), std::invalid_argument);
}

TEST(OctomapMessage, FromTheCompactMapIsTheTreesMessageAndReadsBack) {
  const HullResult result = buildHull(test::sceneHullInput("sculpture", 8, "ring"), [] {
    HullConfig config;
    config.max_depth = 6;
    return config;
  }());
  const std::unique_ptr<octomap::OcTree> tree = toOctomap(result.hull);
  const sift_hull::Octomap compact = rc::octomapMessage(compactOctomap(result.hull), mapHeader());
  const sift_hull::Octomap reference = rc::octomapMessage(*tree, mapHeader());
  EXPECT_EQ(compact.binary, reference.binary);
  EXPECT_EQ(compact.id, reference.id);
  EXPECT_EQ(compact.resolution, reference.resolution);
  EXPECT_EQ(compact.header.stamp, reference.header.stamp);
  EXPECT_TRUE(compact.data == reference.data)
      << compact.data.size() << " against " << reference.data.size() << " bytes";
  EXPECT_EQ(rc::octreeFromMessage(compact)->getNumLeafNodes(), tree->getNumLeafNodes());
}

TEST(OctreeFromMessage, RefusesOtherTreesBadResolutionsAndCutData) {
  const MixedTree mixed;
  sift_hull::Octomap message = rc::octomapFullMessage(mixed.tree, mapHeader());
  sift_hull::Octomap color = message, zero = message, nan = message, cut = message;
  color.id = "ColorOcTree";
  zero.resolution = 0.0;
  nan.resolution = std::nan("");
  cut.data.resize(cut.data.size() / 2);
  EXPECT_THROW(rc::octreeFromMessage(color), std::invalid_argument);
  EXPECT_THROW(rc::octreeFromMessage(zero), std::invalid_argument);
  EXPECT_THROW(rc::octreeFromMessage(nan), std::invalid_argument);
  EXPECT_THROW(rc::octreeFromMessage(cut), std::invalid_argument);
}

TEST(FreeCellsMarkers, OneCubeListPerDepthLevelOfTheFreeLeavesOnlyTheEmptyLevelsDeleted) {
  MixedTree mixed;
  // An aligned 2x2x2 block of free voxels at x, y, z in [-0.4, -0.2): one leaf of twice the size.
  for (int c = 0; c < 8; ++c) {
    mixed.tree.setNodeValue(-0.35 + kRes * (c & 1), -0.35 + kRes * (c >> 1 & 1),
                            -0.35 + kRes * (c >> 2 & 1), mixed.tree.getClampingThresMinLog());
  }
  mixed.tree.prune();
  const visualization_msgs::MarkerArray markers = rc::freeCellsMarkers(mixed.tree, mapHeader());
  ASSERT_EQ(markers.markers.size(), mixed.tree.getTreeDepth() + 1u);
  double volume_m3 = 0.0;
  size_t added = 0;
  for (size_t level = 0; level < markers.markers.size(); ++level) {
    const visualization_msgs::Marker& m = markers.markers[level];
    EXPECT_EQ(m.id, static_cast<int>(level));
    EXPECT_NEAR(m.scale.x, mixed.tree.getNodeSize(static_cast<unsigned>(level)), 1e-12);
    EXPECT_EQ(m.action, m.points.empty() ? visualization_msgs::Marker::DELETE
                                         : visualization_msgs::Marker::ADD);
    EXPECT_TRUE(m.ns == "free_cells" && m.type == visualization_msgs::Marker::CUBE_LIST);
    EXPECT_EQ(m.header.frame_id, "map");
    if (m.points.empty()) continue;
    ++added;
    EXPECT_EQ(m.points.size(), m.scale.x > 1.5 * kRes ? 1u : 6u);
    EXPECT_TRUE(m.color.b == 1.0f && m.color.a == 1.0f && m.color.r == 0.0f);
    for (const geometry_msgs::Point& p : m.points) {
      EXPECT_FALSE(mixed.tree.isNodeOccupied(mixed.tree.search(p.x, p.y, p.z)));
    }
    volume_m3 += m.points.size() * std::pow(m.scale.x, 3);
  }
  EXPECT_NEAR(volume_m3, 14 * std::pow(kRes, 3), 1e-12);
  EXPECT_EQ(added, 2u);  // the block's leaf and the single voxels
  EXPECT_EQ(rc::occupiedCellsMarkers(mixed.tree, mapHeader()).markers.front().ns, "occupied_cells");
}

TEST(BoxFromCorners, GivesTheCornersAsTheyAreForIsValidClearBoxToCheck) {
  geometry_msgs::Point min, max;
  min.x = -1.0, min.y = 2.0, min.z = 0.5;
  max.x = 1.5, max.y = 2.0, max.z = 0.25;
  const Box3d box = rc::boxFromCorners(min, max);
  EXPECT_EQ(box.min_W, Eigen::Vector3d(-1.0, 2.0, 0.5));
  EXPECT_EQ(box.max_W, Eigen::Vector3d(1.5, 2.0, 0.25));
  EXPECT_FALSE(isValidClearBox(box));  // z: min > max
  max.z = 0.5;
  EXPECT_TRUE(isValidClearBox(rc::boxFromCorners(min, max)));  // a flat box is a box
}

TEST(OctomapServices, HaveOctomapMsgsMd5sums) {
  // genmsg's md5 of octomap_msgs/GetOctomap.srv and BoundingBoxQuery.srv, computed from
  // octomap_msgs' own text with genmsg.gentools.compute_md5 (md5 of "9a45536b45c5e409cd49f04bb2d
  // 9999f map" and of "4a842b65f413084dc2b10fb484ea7f17 min\n4a842b65f413084dc2b10fb484ea7f17
  // max"): a client built against octomap_msgs can call the node's services.
  EXPECT_STREQ(ros::service_traits::md5sum<sift_hull::GetOctomap>(),
               "be9d2869d24fe40d6bc21ac21f6bb2c5");
  EXPECT_STREQ(ros::service_traits::md5sum<sift_hull::BoundingBoxQuery>(),
               "93aa3d73b866f04880927745f4aab303");
  EXPECT_STREQ(ros::message_traits::md5sum<sift_hull::Octomap>(),
               "9a45536b45c5e409cd49f04bb2d9999f");
}

TEST(SurfacePointsMessage, RoundTripsIntoTheWorldAndRefusesBadMessages) {
  const Eigen::Matrix3d K = (Eigen::Matrix3d() << 500, 0, 320, 0, 500, 240, 0, 0, 1).finished();
  const PinholeCamera left(K, Eigen::Matrix3d::Identity(), Eigen::Vector3d::Zero());
  const PinholeCamera right(K, Eigen::Matrix3d::Identity(), Eigen::Vector3d(-0.2, 0.0, 0.0));
  std::vector<SurfacePoint> points(2);
  points[0].X_W = Eigen::Vector3d(0.1, 0.2, 2.0), points[0].reprojection_px = 0.3;
  points[1].X_W = Eigen::Vector3d(-0.3, 0.0, 3.0), points[1].reprojection_px = 0.0;
  const sift_hull::SurfacePoints message =
      rc::surfacePointsMessage(mapHeader(), left, right, points);
  // The message's frame 1 m along the world's x and turned 90 degrees about z.
  Eigen::Isometry3d T_W_F = Eigen::Isometry3d::Identity();
  T_W_F.linear() = Eigen::AngleAxisd(M_PI / 2, Eigen::Vector3d::UnitZ()).toRotationMatrix();
  T_W_F.translation() = Eigen::Vector3d(1.0, 0.0, 0.0);
  PinholeCamera l, r;
  std::vector<SurfacePoint> read;
  std::string why_not;
  ASSERT_TRUE(rc::surfacePointsFromMessage(message, T_W_F, &l, &r, &read, &why_not)) << why_not;
  ASSERT_EQ(read.size(), 2u);
  for (size_t i = 0; i < 2; ++i) {
    EXPECT_LT((read[i].X_W - T_W_F * points[i].X_W).norm(), 1e-9);
    EXPECT_FLOAT_EQ(read[i].reprojection_px, points[i].reprojection_px);
    EXPECT_EQ(read[i].views, std::vector<uint32_t>({0, 1}));
    EXPECT_GT(read[i].depth_sigma_m, 0.0);
    // Each camera sees the world point where the original saw the point in the frame.
    EXPECT_LT((l.project(read[i].X_W) - left.project(points[i].X_W)).norm(), 1e-6);
    EXPECT_LT((r.project(read[i].X_W) - right.project(points[i].X_W)).norm(), 1e-6);
  }
  sift_hull::SurfacePoints short_errors = message, nan = message, zero_k = message, bad_r = message,
                           negative = message;
  short_errors.reprojection_px.pop_back();
  nan.points[1].z = std::nan("");
  zero_k.left_K.fill(0.0);
  bad_r.right_R[0] = 2.0;
  negative.reprojection_px[0] = -1.0f;
  for (const sift_hull::SurfacePoints* bad : {&short_errors, &nan, &zero_k, &bad_r, &negative}) {
    EXPECT_FALSE(rc::surfacePointsFromMessage(*bad, T_W_F, &l, &r, &read, &why_not));
    EXPECT_FALSE(why_not.empty());
  }
}

}  // namespace
}  // namespace sift_hull
