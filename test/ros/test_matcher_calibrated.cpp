// The matcher node with cameras: a calibrated stereo pair (camera_info, tf between the cameras,
// exact or approximate pairing) and one moving camera frame to frame (poses from tf, a keyframe).
// Part of test_matcher_node; the rostests choose cases by --gtest_filter.

#include "matcher_node_fixture.h"

namespace sift_hull {
namespace {

/// The same pair with camera_info and the right camera's pose relative to the left in tf.
class CalibratedMatcherTest : public MatcherNodeTest {
 protected:
  void SetUp() override {
    MatcherNodeTest::SetUp();
    left_info_pub_ = nh_.advertise<sensor_msgs::CameraInfo>("left/camera_info", 5);
    right_info_pub_ = nh_.advertise<sensor_msgs::CameraInfo>("right/camera_info", 5);
    points_sub_ = nh_.subscribe("points", 5, &CalibratedMatcherTest::onPoints, this);
    // The left camera's frame is the "world" of the right camera's pose.
    const PinholeCamera& left = left_.view.camera;
    const PinholeCamera& right = right_.view.camera;
    const PinholeCamera right_in_left(right.K(), right.R() * left.R().transpose(),
                                      right.t() - right.R() * left.R().transpose() * left.t());
    tf_.sendTransform(ros_conversions::cameraPoseMessage(right_in_left, "left", "right", {}));
    ASSERT_TRUE(waitFor([&] {
      return left_info_pub_.getNumSubscribers() > 0 && right_info_pub_.getNumSubscribers() > 0 &&
             points_sub_.getNumPublishers() > 0;
    }));
  }

  /// The pair with its camera_infos, the right camera's stamped `right_delay` after the left's.
  ros::Time publishCalibratedPair(const ros::Duration& right_delay = ros::Duration(0)) {
    const ros::Time stamp = ros::Time::now();
    std_msgs::Header header;
    header.stamp = stamp;
    header.frame_id = "left";
    left_info_pub_.publish(
        ros_conversions::cameraInfoMessage(left_.view.camera, left_.image.size(), header));
    header.stamp = stamp + right_delay;
    header.frame_id = "right";
    right_info_pub_.publish(
        ros_conversions::cameraInfoMessage(right_.view.camera, right_.image.size(), header));
    left_pub_.publish(bgrImage(left_.image, stamp, "left"));
    right_pub_.publish(bgrImage(right_.image, header.stamp, "right"));
    return stamp;
  }

  void onPoints(const sensor_msgs::PointCloud2ConstPtr& message) { points_ = message; }

  tf2_ros::StaticTransformBroadcaster tf_;
  ros::Publisher left_info_pub_, right_info_pub_;
  ros::Subscriber points_sub_;
  sensor_msgs::PointCloud2ConstPtr points_;
};

TEST_F(CalibratedMatcherTest, FiltersByEpipolarLinesAndTriangulatesOntoTheScene) {
  const ros::Time stamp = publishCalibratedPair();
  ASSERT_TRUE(answeredAtLeast(stamp)) << "no correspondences for the calibrated pair";
  ASSERT_EQ(last_->filters, (std::vector<std::string>{"epipolar", "gsc"}));
  ASSERT_TRUE(waitFor([&] { return points_ && points_->header.stamp == stamp; }));
  EXPECT_EQ(points_->header.frame_id, "left");
  // Each point, in the left camera's frame, lies where the left depth map says (within 2 %).
  const PinholeCamera camera(left_.view.camera.K(), Eigen::Matrix3d::Identity(),
                             Eigen::Vector3d::Zero());
  const test::DepthAgreement agreement = test::depthAgreement(*points_, camera, left_.depth);
  const size_t points = agreement.points, on_surface = agreement.on_surface;
  ASSERT_GE(points, 20u);
  EXPECT_GE(static_cast<double>(on_surface) / points, 0.9);

  // surface_points (for the hull node): the same points with both cameras, in the left frame,
  // published once someone listens.
  sift_hull::SurfacePointsConstPtr surface;
  ros::Subscriber surface_sub = nh_.subscribe<sift_hull::SurfacePoints>(
      "surface_points", 5, [&](const sift_hull::SurfacePointsConstPtr& m) { surface = m; });
  ASSERT_TRUE(waitFor([&] { return surface_sub.getNumPublishers() > 0; }));
  const ros::Time again = publishCalibratedPair();
  ASSERT_TRUE(waitFor([&] { return surface && surface->header.stamp == again; }))
      << "no surface_points";
  EXPECT_EQ(surface->header.frame_id, "left");
  PinholeCamera left, right;
  std::vector<SurfacePoint> surface_points;
  std::string why_not;
  ASSERT_TRUE(ros_conversions::surfacePointsFromMessage(*surface, Eigen::Isometry3d::Identity(),
                                                        &left, &right, &surface_points, &why_not))
      << why_not;
  EXPECT_EQ(surface_points.size(), static_cast<size_t>(points_->width) * points_->height);
  EXPECT_LT((left.centre()).norm(), 1e-9);  // the left camera at the left frame's origin
  size_t small_error = 0;
  for (const SurfacePoint& p : surface_points) small_error += p.reprojection_px < 1.0 ? 1 : 0;
  EXPECT_GE(small_error, 0.9 * surface_points.size());
}

/// ~frame_to_frame with ~calibrated: one moving camera (frame `camera`), its pose in `world` from
/// tf at each frame's stamp, the camera_info beside `image`. Views 0 and 1 of the scene are two
/// positions of the camera.
class CalibratedFrameToFrameMatcherTest : public FrameToFrameMatcherTest {
 protected:
  void SetUp() override {
    FrameToFrameMatcherTest::SetUp();
    info_pub_ = nh_.advertise<sensor_msgs::CameraInfo>("camera_info", 5);
    tf_pub_ = nh_.advertise<tf2_msgs::TFMessage>("/tf", 100);
    points_sub_ = nh_.subscribe("points", 5, &CalibratedFrameToFrameMatcherTest::onPoints, this);
    // The node's tf listener connected before any pose is sent (a pose sent earlier is lost).
    ASSERT_TRUE(waitFor([&] {
      return info_pub_.getNumSubscribers() > 0 && points_sub_.getNumPublishers() > 0 &&
             tf_pub_.getNumSubscribers() > 0;
    }));
  }

  /// A frame of `view` at `stamp`, with its camera_info, and its pose in tf unless `posed` is
  /// false; `pose` replaces the view's own camera pose where given.
  void publishFrame(const RenderedView& view, const ros::Time& stamp, bool posed = true,
                    const PinholeCamera* pose = nullptr) {
    if (posed) {
      tf2_msgs::TFMessage poses;
      poses.transforms.push_back(ros_conversions::cameraPoseMessage(pose ? *pose : view.view.camera,
                                                                    "world", "camera", stamp));
      tf_pub_.publish(poses);
    }
    std_msgs::Header header;
    header.stamp = stamp;
    header.frame_id = "camera";
    info_pub_.publish(
        ros_conversions::cameraInfoMessage(view.view.camera, view.image.size(), header));
    frame_pub_.publish(bgrImage(view.image, stamp, "camera"));
  }

  void onPoints(const sensor_msgs::PointCloud2ConstPtr& message) { points_ = message; }

  ros::Publisher info_pub_, tf_pub_;
  ros::Subscriber points_sub_;
  sensor_msgs::PointCloud2ConstPtr points_;
};

TEST_F(CalibratedFrameToFrameMatcherTest, MatchesTheKeyframeOnceTheCameraHasMoved) {
  // The keyframe; the same pose again (no baseline: skipped); then the camera moved: matched.
  const ros::Time first = ros::Time::now();
  publishFrame(left_, first);
  ros::WallDuration(0.2).sleep();
  const ros::Time still = first + ros::Duration(0.5);
  publishFrame(left_, still);
  ros::WallDuration(0.2).sleep();
  const ros::Time moved = still + ros::Duration(0.5);
  publishFrame(right_, moved);
  ASSERT_TRUE(waitFor([&] { return last_ && last_->right_header.stamp == moved; }))
      << "no correspondences once the camera moved";
  EXPECT_EQ(last_->header.stamp, first);  // the keyframe is the left image
  ASSERT_EQ(last_->filters, (std::vector<std::string>{"epipolar", "gsc"}));
  EXPECT_GE(last_->matches.size(), 50u);
  expectNoneAnswered({still});
  // The points, in the keyframe camera's frame, lie where its depth map says.
  ASSERT_TRUE(waitFor([&] { return points_ && points_->header.stamp == first; }));
  EXPECT_EQ(points_->header.frame_id, "camera");
  const PinholeCamera camera(left_.view.camera.K(), Eigen::Matrix3d::Identity(),
                             Eigen::Vector3d::Zero());
  const test::DepthAgreement agreement = test::depthAgreement(*points_, camera, left_.depth);
  ASSERT_GE(agreement.points, 20u);
  EXPECT_GE(static_cast<double>(agreement.on_surface) / agreement.points, 0.9);

  // A frame whose pose never comes is dropped after ~pose_timeout_s; every frame is counted.
  publishFrame(left_, moved + ros::Duration(0.5), false);
  EXPECT_EQ(
      test::diagnosticValue(nh_, "matcher", "frames without pose", [](double v) { return v >= 1; }),
      1.0);
  const auto count = [&](const std::string& key) {
    return test::diagnosticValue(nh_, "matcher", key, [](double) { return true; });
  };
  EXPECT_EQ(count("frames received"), 4.0);
  EXPECT_EQ(count("frames started a keyframe"), 1.0);
  EXPECT_EQ(count("frames skipped (baseline below ~min_baseline_m)"), 1.0);
  EXPECT_EQ(count("frames matched with the keyframe"), 1.0);
}

TEST_F(CalibratedFrameToFrameMatcherTest, ATurnedFrameStartsAKeyframeAndAnOlderOneIsRefused) {
  // The counts go on across the cases of one node: each is checked as a rise from its value now.
  const std::vector<std::string> keys = {
      "frames received", "frames started a keyframe", "frames out of order",
      "frames turned beyond ~max_rotation_deg", "frames matched with the keyframe"};
  std::map<std::string, double> before;
  for (const std::string& key : keys) {
    before[key] = test::diagnosticValue(nh_, "matcher", key, [](double) { return true; });
  }
  const auto count = [&](const std::string& key, double rise) {
    return test::diagnosticValue(nh_, "matcher", key,
                                 [&](double v) { return v >= before[key] + rise; }) -
           before[key];
  };
  const ros::Time first = ros::Time::now();
  publishFrame(left_, first);  // the keyframe
  ASSERT_EQ(count("frames started a keyframe", 1), 1.0);
  publishFrame(left_, first - ros::Duration(0.5));  // older than the keyframe: refused
  ASSERT_EQ(count("frames out of order", 1), 1.0);
  // The right view's camera turned 120 degrees about its optical axis (centre unchanged): beyond
  // ~max_rotation_deg (90), so it is not matched and becomes the keyframe.
  const PinholeCamera& right = right_.view.camera;
  const Eigen::Matrix3d turn =
      Eigen::AngleAxisd(120.0 * M_PI / 180.0, Eigen::Vector3d::UnitZ()).toRotationMatrix();
  const PinholeCamera turned(right.K(), turn * right.R(), turn * right.t());
  const ros::Time second = first + ros::Duration(0.5);
  publishFrame(right_, second, true, &turned);
  ASSERT_EQ(count("frames turned beyond ~max_rotation_deg", 1), 1.0);
  // The same camera moved 5 cm sideways without turning: matched with the turned keyframe.
  const Eigen::Vector3d centre =
      turned.centre() + turned.R().transpose() * Eigen::Vector3d(0.05, 0, 0);
  const PinholeCamera moved(turned.K(), turned.R(), -turned.R() * centre);
  const ros::Time third = second + ros::Duration(0.5);
  publishFrame(right_, third, true, &moved);
  ASSERT_TRUE(waitFor([&] { return last_ && last_->right_header.stamp == third; }))
      << "no correspondences with the turned keyframe";
  EXPECT_EQ(last_->header.stamp, second);
  EXPECT_EQ(count("frames matched with the keyframe", 1), 1.0);
  expectNoneAnswered({first, first - ros::Duration(0.5)});
  EXPECT_EQ(count("frames received", 4), 4.0);
}

/// The matcher's /diagnostics counts as rises from their values when it was made (the counts go
/// on across the cases of one node).
class Rises {
 public:
  Rises(ros::NodeHandle& nh, const std::vector<std::string>& keys) : nh_(nh) {
    for (const std::string& key : keys) {
      before_[key] = test::diagnosticValue(nh_, "matcher", key, [](double) { return true; });
    }
  }
  /// The rise of `key`, once it has risen by `rise` at least (or at the deadline).
  double operator()(const std::string& key, double rise) {
    const double base = before_.at(key);
    return test::diagnosticValue(nh_, "matcher", key, [&](double v) { return v >= base + rise; }) -
           base;
  }

 private:
  ros::NodeHandle& nh_;
  std::map<std::string, double> before_;
};

TEST_F(CalibratedFrameToFrameMatcherTest, ATfStampAtTheEndOfTimeOrAheadIsRefusedAndPosesGoOn) {
  Rises rises(nh_, {"tf transforms refused", "frames matched with the keyframe"});
  const ros::Time now = ros::Time::now();
  tf2_msgs::TFMessage bad;
  bad.transforms.push_back(ros_conversions::cameraPoseMessage(left_.view.camera, "world", "camera",
                                                              ros::Time(4294967290u, 0)));
  bad.transforms.push_back(ros_conversions::cameraPoseMessage(left_.view.camera, "world", "camera",
                                                              now + ros::Duration(100.0)));
  tf_pub_.publish(bad);
  ASSERT_EQ(rises("tf transforms refused", 2), 2.0);
  // The buffer kept its poses and takes new ones: a keyframe and a moved frame are matched.
  const ros::Time first = now + ros::Duration(0.1);
  publishFrame(left_, first);
  ros::WallDuration(0.2).sleep();
  const ros::Time moved = first + ros::Duration(0.5);
  publishFrame(right_, moved);
  ASSERT_TRUE(waitFor([&] { return last_ && last_->right_header.stamp == moved; }))
      << "no correspondences after the refused transforms";
  EXPECT_EQ(last_->header.stamp, first);
  EXPECT_EQ(rises("frames matched with the keyframe", 1), 1.0);
}

TEST_F(CalibratedFrameToFrameMatcherTest, AnUnusableFrameNeverBecomesTheKeyframe) {
  Rises rises(nh_, {"frames received", "frames unusable", "frames matched with the keyframe",
                    "frames started a keyframe", "frames turned beyond ~max_rotation_deg"});
  // A turned frame starts the keyframe whatever came before (the counts go on across cases).
  const PinholeCamera& left = left_.view.camera;
  const Eigen::Matrix3d turn = Eigen::AngleAxisd(M_PI, Eigen::Vector3d::UnitZ()).toRotationMatrix();
  const PinholeCamera upside_down(left.K(), turn * left.R(), turn * left.t());
  const ros::Time start = ros::Time::now();
  publishFrame(left_, start, true, &upside_down);
  ros::WallDuration(0.2).sleep();
  const ros::Time first = start + ros::Duration(0.2);
  publishFrame(left_, first);  // turned back: the keyframe
  ASSERT_EQ(rises("frames received", 2), 2.0);
  // A frame whose camera_info has no focal length, a 16-bit frame and one stamped a minute
  // ahead of the clock: refused before their pose is asked for.
  std_msgs::Header header;
  header.frame_id = "camera";
  header.stamp = first + ros::Duration(0.1);
  sensor_msgs::CameraInfo no_focal =
      ros_conversions::cameraInfoMessage(right_.view.camera, right_.image.size(), header);
  no_focal.K[0] = 0.0;
  info_pub_.publish(no_focal);
  frame_pub_.publish(bgrImage(right_.image, header.stamp, "camera"));
  header.stamp = first + ros::Duration(0.2);
  sensor_msgs::Image deep = bgrImage(right_.image, header.stamp, "camera");
  deep.encoding = "16UC1";
  deep.step = deep.width * 2;
  deep.data.resize(size_t{deep.step} * deep.height);
  info_pub_.publish(
      ros_conversions::cameraInfoMessage(right_.view.camera, right_.image.size(), header));
  frame_pub_.publish(deep);
  publishFrame(right_, ros::Time::now() + ros::Duration(60.0), false);
  ASSERT_EQ(rises("frames unusable", 3), 3.0);
  // The next good frame is matched with the keyframe, not with any of them.
  const ros::Time moved = first + ros::Duration(0.5);
  publishFrame(right_, moved);
  ASSERT_TRUE(waitFor([&] { return last_ && last_->right_header.stamp == moved; }))
      << "the good frame after the unusable ones was not matched";
  EXPECT_EQ(last_->header.stamp, first);
  EXPECT_EQ(rises("frames matched with the keyframe", 1), 1.0);
  EXPECT_EQ(rises("frames received", 6), 6.0);
}

TEST_F(CalibratedFrameToFrameMatcherTest, TwoFramesOfOneStampAreEachCounted) {
  Rises rises(nh_, {"frames received", "frames without pose"});
  const ros::Time stamp = ros::Time::now();
  publishFrame(left_, stamp, false);
  // Apart, so that the synchroniser pairs each image with its own camera_info.
  ros::WallDuration(0.2).sleep();
  publishFrame(left_, stamp, false);
  // One refused at once (its twin waits), the other after ~pose_timeout_s: received = the sum.
  ASSERT_EQ(rises("frames received", 2), 2.0);
  EXPECT_EQ(rises("frames without pose", 2), 2.0);
}

/// ~approximate_sync with ~calibrated: the images and camera_infos pair by the nearest stamps.
class CalibratedApproximateMatcherTest : public CalibratedMatcherTest {};

TEST_F(CalibratedApproximateMatcherTest, PairsAStereoPairWhoseStampsDiffer) {
  // Each set is paired once a later one shows that no nearer stamps will come.
  std::set<ros::Time> sent;
  ASSERT_TRUE(waitFor([&] {
    if (last_) return true;
    sent.insert(publishCalibratedPair(ros::Duration(0.004)));
    ros::WallDuration(0.2).sleep();
    return false;
  })) << "no correspondences for stereo pairs 4 ms apart";
  EXPECT_EQ(sent.count(last_->header.stamp), 1u);
  EXPECT_EQ(last_->right_header.stamp, last_->header.stamp + ros::Duration(0.004));
  ASSERT_EQ(last_->filters, (std::vector<std::string>{"epipolar", "gsc"}));
  EXPECT_GE(last_->matches.size(), 50u);
}

}  // namespace
}  // namespace sift_hull
