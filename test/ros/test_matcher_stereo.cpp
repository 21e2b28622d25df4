// The calibrated matcher on a rectified pair whose images share one frame (stereo_image_proc's
// convention): the right camera comes from the baseline in its P, not from tf. Epipolar matches
// and points at the scene's depth; a pair with no baseline gives a specific error on /rosout.

#include <gtest/gtest.h>
#include <ros/ros.h>
#include <sensor_msgs/PointCloud2.h>
#include <sensor_msgs/point_cloud2_iterator.h>

#include <cmath>

#include "bad_inputs.h"
#include "cloud_checks.h"
#include "lib/conversions.h"
#include "ros_wait.h"
#include "sift_hull/Correspondences.h"
#include "sift_hull/synthetic/scene.h"
#include "sift_hull/synthetic/shape.h"

namespace sift_hull {
namespace {

using bad_inputs::loggedError;
using bad_inputs::rosout;
using test::waitFor;

constexpr double kBaseline_m = 0.3;

class SharedFrameMatcherTest : public ::testing::Test {
 protected:
  void SetUp() override {
    SceneConfig config;
    config.width_px = 320, config.height_px = 240;
    const Shape shape = Shape::byName(config.shape);
    const CalibratedView left_view = sceneCameras(config, shape)[0];
    CalibratedView right_view = left_view;
    const PinholeCamera& L = left_view.camera;
    right_view.camera = PinholeCamera(L.K(), L.R(), L.t() - Eigen::Vector3d(kBaseline_m, 0, 0));
    left_ = renderView(shape, left_view, {320, 240}, config.seed);
    right_ = renderView(shape, right_view, {320, 240}, config.seed);
    left_pub_ = nh_.advertise<sensor_msgs::Image>("left/image", 5);
    right_pub_ = nh_.advertise<sensor_msgs::Image>("right/image", 5);
    left_info_pub_ = nh_.advertise<sensor_msgs::CameraInfo>("left/camera_info", 5);
    right_info_pub_ = nh_.advertise<sensor_msgs::CameraInfo>("right/camera_info", 5);
    sub_ = nh_.subscribe("correspondences", 5, &SharedFrameMatcherTest::onCorrespondences, this);
    points_sub_ = nh_.subscribe("points", 5, &SharedFrameMatcherTest::onPoints, this);
    ASSERT_TRUE(waitFor([&] {
      return left_pub_.getNumSubscribers() > 0 && right_pub_.getNumSubscribers() > 0 &&
             left_info_pub_.getNumSubscribers() > 0 && right_info_pub_.getNumSubscribers() > 0;
    })) << "the matcher did not connect";
  }

  /// Both images in frame "stereo"; the right P's fourth column is -fx B.
  ros::Time publish(double baseline_m) {
    std_msgs::Header header;
    header.stamp = ros::Time::now();
    header.frame_id = "stereo";
    const PinholeCamera& L = left_.view.camera;
    const PinholeCamera at_origin(L.K(), Eigen::Matrix3d::Identity(), Eigen::Vector3d::Zero());
    sensor_msgs::CameraInfo left =
        ros_conversions::cameraInfoMessage(at_origin, {320, 240}, header);
    sensor_msgs::CameraInfo right = left;
    right.P[3] = -L.K()(0, 0) * baseline_m;
    left_info_pub_.publish(left);
    right_info_pub_.publish(right);
    left_pub_.publish(ros_conversions::imageMessage(left_.image, header));
    right_pub_.publish(ros_conversions::imageMessage(right_.image, header));
    return header.stamp;
  }

  void onCorrespondences(const sift_hull::CorrespondencesConstPtr& message) { last_ = message; }
  void onPoints(const sensor_msgs::PointCloud2ConstPtr& message) { points_ = message; }

  ros::NodeHandle nh_;
  ros::Publisher left_pub_, right_pub_, left_info_pub_, right_info_pub_;
  ros::Subscriber sub_, points_sub_;
  RenderedView left_, right_;
  sift_hull::CorrespondencesConstPtr last_;
  sensor_msgs::PointCloud2ConstPtr points_;
};

TEST_F(SharedFrameMatcherTest, TakesTheBaselineFromPAndTriangulatesOntoTheScene) {
  const ros::Time stamp = publish(kBaseline_m);
  ASSERT_TRUE(waitFor([&] { return last_ && last_->header.stamp == stamp; }));
  ASSERT_TRUE(waitFor([&] { return points_ && points_->header.stamp == stamp; }));
  size_t kept = 0;
  for (const sift_hull::Correspondence& c : last_->matches) kept += c.kept_by & 1u;
  EXPECT_GE(kept, 50u) << "of " << last_->matches.size() << " matches";
  const PinholeCamera camera(left_.view.camera.K(), Eigen::Matrix3d::Identity(),
                             Eigen::Vector3d::Zero());
  const test::DepthAgreement agreement = test::depthAgreement(*points_, camera, left_.depth);
  const size_t points = agreement.points, on_surface = agreement.on_surface;
  ASSERT_GE(points, 20u);
  EXPECT_GE(static_cast<double>(on_surface) / points, 0.9) << on_surface << " of " << points;
  RecordProperty("epipolar_kept", std::to_string(kept));
  RecordProperty("points_within_2_percent",
                 std::to_string(on_surface) + " of " + std::to_string(points));
}

TEST_F(SharedFrameMatcherTest, NoBaselineIsASpecificErrorAndNoOutput) {
  const size_t since = rosout().mark();
  const ros::Time stamp = publish(0.0);
  EXPECT_TRUE(loggedError("/matcher", {"pair ignored", "no baseline", "'stereo'"}, since));
  ros::WallDuration(0.5).sleep();
  ros::spinOnce();
  EXPECT_FALSE(last_ && last_->header.stamp == stamp);
  // A good pair after it is matched as usual.
  const ros::Time good = publish(kBaseline_m);
  EXPECT_TRUE(waitFor([&] { return points_ && points_->header.stamp == good; }));
}

}  // namespace
}  // namespace sift_hull

int main(int argc, char** argv) {
  ::testing::InitGoogleTest(&argc, argv);
  ros::init(argc, argv, "test_matcher_stereo");
  ros::NodeHandle nh;
  sift_hull::bad_inputs::rosout().start(nh);
  return RUN_ALL_TESTS();
}
