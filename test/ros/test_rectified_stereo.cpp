// The matcher behind Debian's image_proc: distorted raw views (plumb_bob camera_info) go through
// image_proc's rectify nodelets, and their image_rect, with the camera_info beside it, to the
// matcher with ~calibrated, ~rectified and the epipolar filter. The matches and points are scored
// against the rendered scene's depth. Every wait has a deadline.

#include <gtest/gtest.h>
#include <ros/ros.h>
#include <sensor_msgs/CameraInfo.h>
#include <sensor_msgs/Image.h>
#include <sensor_msgs/PointCloud2.h>
#include <sensor_msgs/point_cloud2_iterator.h>
#include <tf2_ros/static_transform_broadcaster.h>

#include <cmath>

#include "cloud_checks.h"
#include "lib/conversions.h"
#include "ros_wait.h"
#include "sift_hull/Correspondences.h"
#include "sift_hull/eval/match_evaluation.h"
#include "sift_hull/synthetic/scene.h"

namespace sift_hull {
namespace {

using test::waitFor;

class RectifiedStereoTest : public ::testing::Test {
 protected:
  void SetUp() override {
    SceneConfig config;
    config.width_px = 320, config.height_px = 240;
    config.distortion = {-0.3, 0.1, 0.001, -0.002, 0.0};
    left_ = renderSceneView(config, 0);
    right_ = renderSceneView(config, 1);
    left_image_pub_ = nh_.advertise<sensor_msgs::Image>("/stereo/left/image_raw", 5);
    right_image_pub_ = nh_.advertise<sensor_msgs::Image>("/stereo/right/image_raw", 5);
    left_info_pub_ = nh_.advertise<sensor_msgs::CameraInfo>("/stereo/left/camera_info", 5);
    right_info_pub_ = nh_.advertise<sensor_msgs::CameraInfo>("/stereo/right/camera_info", 5);
    sub_ = nh_.subscribe("correspondences", 5, &RectifiedStereoTest::onCorrespondences, this);
    points_sub_ = nh_.subscribe("points", 5, &RectifiedStereoTest::onPoints, this);
    const PinholeCamera &L = left_.view.camera, &R = right_.view.camera;
    const PinholeCamera right_in_left(R.K(), R.R() * L.R().transpose(),
                                      R.t() - R.R() * L.R().transpose() * L.t());
    tf_.sendTransform(ros_conversions::cameraPoseMessage(right_in_left, "left", "right", {}));
    // Our subscription makes the matcher subscribe image_rect, which makes image_proc subscribe
    // image_raw; camera_info has both of them.
    ASSERT_TRUE(waitFor([&] {
      return left_image_pub_.getNumSubscribers() > 0 && right_image_pub_.getNumSubscribers() > 0 &&
             left_info_pub_.getNumSubscribers() > 1 && right_info_pub_.getNumSubscribers() > 1;
    })) << "image_proc and the matcher did not connect";
  }

  void publish(const ros::Time& stamp) {
    std_msgs::Header header;
    header.stamp = stamp;
    const RenderedView* views[2] = {&left_, &right_};
    ros::Publisher* info_pubs[2] = {&left_info_pub_, &right_info_pub_};
    ros::Publisher* image_pubs[2] = {&left_image_pub_, &right_image_pub_};
    for (int i = 0; i < 2; ++i) {
      header.frame_id = i == 0 ? "left" : "right";
      info_pubs[i]->publish(ros_conversions::cameraInfoMessage(views[i]->view.camera,
                                                               views[i]->image.size(), header));
      image_pubs[i]->publish(ros_conversions::imageMessage(views[i]->image, header));
    }
  }

  /// Publishes the pair until its correspondences and points come (the first messages may find
  /// connections still being made).
  bool answered() {
    for (int attempt = 0; attempt < 6; ++attempt) {
      const ros::Time stamp = ros::Time::now();
      publish(stamp);
      if (waitFor(
              [&] {
                return last_ && last_->header.stamp == stamp && points_ &&
                       points_->header.stamp == stamp;
              },
              5.0)) {
        return true;
      }
    }
    return false;
  }

  void onCorrespondences(const sift_hull::CorrespondencesConstPtr& message) { last_ = message; }
  void onPoints(const sensor_msgs::PointCloud2ConstPtr& message) { points_ = message; }

  ros::NodeHandle nh_;
  ros::Publisher left_image_pub_, right_image_pub_, left_info_pub_, right_info_pub_;
  ros::Subscriber sub_, points_sub_;
  tf2_ros::StaticTransformBroadcaster tf_;
  RenderedView left_, right_;
  sift_hull::CorrespondencesConstPtr last_;
  sensor_msgs::PointCloud2ConstPtr points_;
};

/// The matches in raw pixels: the rectified image's pixels are ideal ones of K (P = K [I | 0]).
PutativeMatches rawMatches(const sift_hull::Correspondences& message, const PinholeCamera& left,
                           const PinholeCamera& right, cv::Size size) {
  PutativeMatches matches;
  matches.left_image_size = matches.right_image_size = size;
  for (const sift_hull::Correspondence& c : message.matches) {
    const int index = static_cast<int>(matches.matches.size());
    const Eigen::Vector2d l = left.distortPixel({c.left.x, c.left.y});
    const Eigen::Vector2d r = right.distortPixel({c.right.x, c.right.y});
    matches.left_keypoints.emplace_back(l.x(), l.y(), c.left.size, c.left.angle);
    matches.right_keypoints.emplace_back(r.x(), r.y(), c.right.size, c.right.angle);
    matches.matches.emplace_back(index, index, c.descriptor_distance);
  }
  return matches;
}

TEST_F(RectifiedStereoTest, KeepsTheCorrectMatchesAndTriangulatesOntoTheScene) {
  ASSERT_TRUE(answered()) << "no correspondences and points for the rectified pair";
  ASSERT_EQ(last_->filters, (std::vector<std::string>{"epipolar"}));
  const PinholeCamera &L = left_.view.camera, &R = right_.view.camera;
  const std::vector<MatchTruth> truth = judgeBySceneDepth(
      rawMatches(*last_, L, R, left_.image.size()), {L, left_.depth}, {R, right_.depth});
  size_t correct = 0, correct_kept = 0;
  for (size_t m = 0; m < truth.size(); ++m) {
    if (truth[m] != MatchTruth::kCorrect) continue;
    ++correct;
    correct_kept += last_->matches[m].kept_by & 1u;
  }
  ASSERT_GE(correct, 30u);
  EXPECT_GE(static_cast<double>(correct_kept) / correct, 0.95) << correct_kept << " of " << correct;
  // Each point, in the left camera's frame, lies where the left depth map says (within 2 %).
  const PinholeCamera camera =
      PinholeCamera(L.K(), Eigen::Matrix3d::Identity(), Eigen::Vector3d::Zero())
          .withDistortion(L.distortion());
  const test::DepthAgreement agreement = test::depthAgreement(*points_, camera, left_.depth);
  const size_t points = agreement.points, on_surface = agreement.on_surface;
  ASSERT_GE(points, 20u);
  EXPECT_GE(static_cast<double>(on_surface) / points, 0.9) << on_surface << " of " << points;
  RecordProperty("correct_matches_kept",
                 std::to_string(correct_kept) + " of " + std::to_string(correct));
  RecordProperty("points_within_2_percent",
                 std::to_string(on_surface) + " of " + std::to_string(points));
}

}  // namespace
}  // namespace sift_hull

int main(int argc, char** argv) {
  ::testing::InitGoogleTest(&argc, argv);
  ros::init(argc, argv, "test_rectified_stereo");
  ros::NodeHandle nh;
  return RUN_ALL_TESTS();
}
