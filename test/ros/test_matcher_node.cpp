// The matcher node wired up: a synthetic stereo pair in, correspondences out with the input stamps
// and a precision against the scene's ground truth; bad pairs answered with an error while later
// good pairs still count. Every wait has a deadline.

#include <dynamic_reconfigure/Reconfigure.h>
#include <dynamic_reconfigure/client.h>
#include <gtest/gtest.h>
#include <ros/ros.h>
#include <sensor_msgs/CompressedImage.h>
#include <sensor_msgs/Image.h>
#include <sensor_msgs/PointCloud2.h>
#include <sensor_msgs/point_cloud2_iterator.h>
#include <tf2_msgs/TFMessage.h>
#include <tf2_ros/static_transform_broadcaster.h>

#include <functional>
#include <limits>
#include <map>
#include <mutex>
#include <opencv2/imgcodecs.hpp>
#include <set>

#include "cloud_checks.h"
#include "diagnostics_wait.h"
#include "lib/conversions.h"
#include "ros_wait.h"
#include "sift_hull/Correspondences.h"
#include "sift_hull/MatcherConfig.h"
#include "sift_hull/eval/match_evaluation.h"
#include "sift_hull/features/labelled_matches.h"
#include "sift_hull/synthetic/scene.h"

namespace sift_hull {
namespace {

using test::kDeadline_s;
using test::waitFor;

sensor_msgs::Image bgrImage(const cv::Mat& image, const ros::Time& stamp,
                            const std::string& frame) {
  std_msgs::Header header;
  header.stamp = stamp;
  header.frame_id = frame;
  return ros_conversions::imageMessage(image, header);
}

PutativeMatches putativesOf(const sift_hull::Correspondences& message, cv::Size size) {
  PutativeMatches matches;
  matches.left_image_size = matches.right_image_size = size;
  for (const sift_hull::Correspondence& c : message.matches) {
    const int index = static_cast<int>(matches.matches.size());
    matches.left_keypoints.emplace_back(c.left.x, c.left.y, c.left.size, c.left.angle);
    matches.right_keypoints.emplace_back(c.right.x, c.right.y, c.right.size, c.right.angle);
    matches.matches.emplace_back(index, index, c.descriptor_distance);
  }
  return matches;
}

class MatcherNodeTest : public ::testing::Test {
 protected:
  /// Whether the node subscribes the inputs this test publishes.
  virtual bool inputsConnected() const {
    return left_pub_.getNumSubscribers() > 0 && right_pub_.getNumSubscribers() > 0;
  }
  virtual void advertise() {
    left_pub_ = nh_.advertise<sensor_msgs::Image>("left/image", 5);
    right_pub_ = nh_.advertise<sensor_msgs::Image>("right/image", 5);
  }

  void SetUp() override {
    SceneConfig config;
    config.width_px = 320;
    config.height_px = 240;
    left_ = renderSceneView(config, 0);
    right_ = renderSceneView(config, 1);
    advertise();
    sub_ = nh_.subscribe("correspondences", 5, &MatcherNodeTest::onCorrespondences, this);
    ASSERT_TRUE(waitFor([&] { return inputsConnected() && sub_.getNumPublishers() > 0; }))
        << "the matcher node did not connect";
  }

  ros::Time publishPair(const cv::Mat& left, const cv::Mat& right) {
    const ros::Time stamp = ros::Time::now();
    if (!left.empty()) left_pub_.publish(bgrImage(left, stamp, "left"));
    if (!right.empty()) right_pub_.publish(bgrImage(right, stamp, "right"));
    return stamp;
  }

  bool answeredAtLeast(const ros::Time& stamp) {
    return waitFor([&] { return last_ && last_->header.stamp >= stamp; });
  }

  void onCorrespondences(const sift_hull::CorrespondencesConstPtr& message) {
    last_ = message;
    answered_.insert(message->header.stamp);
  }

  /// None of `stamps` was answered, however late (the node matches on worker threads).
  void expectNoneAnswered(const std::vector<ros::Time>& stamps) {
    for (const ros::Time& stamp : stamps) EXPECT_EQ(answered_.count(stamp), 0u) << stamp;
  }

  ros::NodeHandle nh_;
  ros::Publisher left_pub_, right_pub_, frame_pub_;
  ros::Subscriber sub_;
  RenderedView left_, right_;
  sift_hull::CorrespondencesConstPtr last_;
  std::set<ros::Time> answered_;
};

TEST_F(MatcherNodeTest, MatchesAPairWithTheInputStampsAndGoodPrecision) {
  const ros::Time stamp = publishPair(left_.image, right_.image);
  ASSERT_TRUE(answeredAtLeast(stamp)) << "no correspondences for the pair";
  EXPECT_EQ(last_->header.stamp, stamp);
  EXPECT_EQ(last_->header.frame_id, "left");
  EXPECT_EQ(last_->right_header.frame_id, "right");
  ASSERT_EQ(last_->filters, (std::vector<std::string>{"gsc", "magsac"}));
  ASSERT_GE(last_->matches.size(), 50u);

  const PutativeMatches putatives = putativesOf(*last_, left_.image.size());
  const std::vector<MatchTruth> truth = judgeBySceneDepth(
      putatives, {left_.view.camera, left_.depth}, {right_.view.camera, right_.depth});
  size_t kept = 0, kept_correct = 0;
  for (size_t m = 0; m < truth.size(); ++m) {
    if (!(last_->matches[m].kept_by & 1u) || truth[m] == MatchTruth::kUnknown) continue;
    ++kept;
    kept_correct += truth[m] == MatchTruth::kCorrect;
  }
  ASSERT_GT(kept, 20u);
  EXPECT_GE(static_cast<double>(kept_correct) / kept, 0.9);  // gsc's precision on this pair
}

TEST_F(MatcherNodeTest, RefusesBadPairsAndCarriesOn) {
  const cv::Mat black = cv::Mat::zeros(left_.image.size(), CV_8UC3);
  std::vector<ros::Time> bad;
  bad.push_back(publishPair(black, black));             // fewer than two keypoints
  bad.push_back(publishPair(left_.image, cv::Mat()));   // a left image without its right partner
  bad.push_back(publishPair(cv::Mat(), right_.image));  // a right image without its left partner
  sensor_msgs::Image empty = bgrImage(left_.image, ros::Time::now(), "left");
  empty.width = empty.height = empty.step = 0;  // an empty image
  empty.data.clear();
  left_pub_.publish(empty);
  right_pub_.publish(bgrImage(right_.image, empty.header.stamp, "right"));
  bad.push_back(empty.header.stamp);
  sensor_msgs::Image depth = bgrImage(right_.image, ros::Time::now(), "right");
  depth.encoding = "16UC1";  // not an 8-bit image
  depth.step = right_.image.cols * 2;
  depth.data.resize(depth.step * depth.height);
  left_pub_.publish(bgrImage(left_.image, depth.header.stamp, "left"));
  right_pub_.publish(depth);
  bad.push_back(depth.header.stamp);
  const ros::Time stamp = publishPair(left_.image, right_.image);
  ASSERT_TRUE(answeredAtLeast(stamp)) << "a good pair after bad ones was not matched";
  ros::WallDuration(0.5).sleep();  // a bad pair that was matched after all would be in by now
  ros::spinOnce();
  expectNoneAnswered(bad);
  EXPECT_EQ(answered_.size(), 1u);
}

TEST_F(MatcherNodeTest, WarnsWhenImagesArriveButDoNotPair) {
  ASSERT_TRUE(answeredAtLeast(publishPair(left_.image, right_.image)));
  // Stereo stamps 5 ms apart under exact sync: nothing pairs.
  const std::string warning = test::warningOf(nh_, "matcher", "have not paired", [&] {
    const ros::Time stamp = ros::Time::now();
    left_pub_.publish(bgrImage(left_.image, stamp, "left"));
    right_pub_.publish(bgrImage(right_.image, stamp + ros::Duration(0.005), "right"));
  });
  ASSERT_FALSE(warning.empty()) << "no WARN on /diagnostics within 20 s";
  EXPECT_NE(warning.find("left/image ("), std::string::npos) << warning;
  EXPECT_NE(warning.find("right/image ("), std::string::npos) << warning;
  EXPECT_NE(warning.find("~approximate_sync"), std::string::npos) << warning;
}

TEST_F(MatcherNodeTest, ThresholdsChangeAtRunTime) {
  const auto keptByGsc = [&] {
    size_t kept = 0;
    for (const sift_hull::Correspondence& c : last_->matches) kept += c.kept_by & 1u;
    return kept;
  };
  ros::Time stamp = publishPair(left_.image, right_.image);
  ASSERT_TRUE(answeredAtLeast(stamp));
  const size_t kept_by_default = keptByGsc();
  ASSERT_GT(kept_by_default, 20u);
  dynamic_reconfigure::Reconfigure change;
  dynamic_reconfigure::DoubleParameter threshold;
  threshold.name = "gsc_max_histogram_distance";
  threshold.value = 0.1;  // the strictest the setting takes (its default: 0.2)
  change.request.config.doubles.push_back(threshold);
  ASSERT_TRUE(ros::service::waitForService("/matcher/set_parameters", ros::Duration(kDeadline_s)));
  ASSERT_TRUE(ros::service::call("/matcher/set_parameters", change));
  stamp = publishPair(left_.image, right_.image);
  ASSERT_TRUE(answeredAtLeast(stamp));
  EXPECT_LT(keptByGsc(), kept_by_default);
  EXPECT_NE(last_->filter_settings.find("\"gsc_max_histogram_distance\":0.1"), std::string::npos)
      << last_->filter_settings;
}

/// `name`'s value in a published reconfigure config (NaN when absent).
double publishedValue(const dynamic_reconfigure::Config& config, const std::string& name) {
  for (const auto& p : config.doubles) {
    if (p.name == name) return p.value;
  }
  return std::numeric_limits<double>::quiet_NaN();
}

TEST_F(MatcherNodeTest, ARefusedValueLeavesTheServerOnTheLastAcceptedOne) {
  std::vector<dynamic_reconfigure::Config> published;  // ~parameter_updates, latched
  ros::Subscriber updates = nh_.subscribe<dynamic_reconfigure::Config>(
      "/matcher/parameter_updates", 5,
      [&](const dynamic_reconfigure::ConfigConstPtr& m) { published.push_back(*m); });
  ASSERT_TRUE(waitFor([&] { return !published.empty(); })) << "no ~parameter_updates";
  sift_hull::MatcherConfig config = sift_hull::MatcherConfig::__getDefault__();
  ASSERT_TRUE(config.__fromMessage__(published.back()));
  dynamic_reconfigure::Client<sift_hull::MatcherConfig> client("/matcher");
  config.max_descriptor_distance = 400.0;
  ASSERT_TRUE(client.setConfiguration(config));
  ASSERT_TRUE(waitFor([&] {
    return !published.empty() &&
           publishedValue(published.back(), "max_descriptor_distance") == 400.0;
  }));
  const size_t accepted = published.size();
  config.max_descriptor_distance = std::numeric_limits<double>::quiet_NaN();
  ASSERT_TRUE(client.setConfiguration(config));  // answered with the config in force
  EXPECT_EQ(config.max_descriptor_distance, 400.0);
  ASSERT_TRUE(waitFor([&] { return published.size() > accepted; })) << "no update for the refusal";
  EXPECT_EQ(publishedValue(published.back(), "max_descriptor_distance"), 400.0);
  const ros::Time stamp = publishPair(left_.image, right_.image);
  ASSERT_TRUE(answeredAtLeast(stamp)) << "no correspondences after the refused value";
  EXPECT_GE(last_->matches.size(), 20u);
  EXPECT_NE(last_->filter_settings.find("\"max_descriptor_distance\":400.0"), std::string::npos)
      << last_->filter_settings;
}

/// One image topic: each frame is matched with the one before it.
class FrameToFrameMatcherTest : public MatcherNodeTest {
 protected:
  bool inputsConnected() const override { return frame_pub_.getNumSubscribers() > 0; }
  void advertise() override { frame_pub_ = nh_.advertise<sensor_msgs::Image>("image", 5); }
};

/// Compressed images (PNG and JPEG) on left/image/compressed and right/image/compressed, with
/// ~image_transport: compressed: decoded by the node when no image_transport plugin does it.
class CompressedMatcherTest : public MatcherNodeTest {
 protected:
  bool inputsConnected() const override {
    return left_compressed_pub_.getNumSubscribers() > 0 &&
           right_compressed_pub_.getNumSubscribers() > 0;
  }
  void advertise() override {
    left_compressed_pub_ = nh_.advertise<sensor_msgs::CompressedImage>("left/image/compressed", 5);
    right_compressed_pub_ =
        nh_.advertise<sensor_msgs::CompressedImage>("right/image/compressed", 5);
  }
  static sensor_msgs::CompressedImage compressed(const cv::Mat& image, const ros::Time& stamp,
                                                 const std::string& frame,
                                                 const std::string& format) {
    sensor_msgs::CompressedImage message;
    message.header.stamp = stamp;
    message.header.frame_id = frame;
    message.format = "bgr8; " + format + " compressed bgr8";
    cv::imencode("." + format, image, message.data);
    return message;
  }

  ros::Publisher left_compressed_pub_, right_compressed_pub_;
};

TEST_F(CompressedMatcherTest, DecodesCompressedPairsAndRefusesUndecodableOnes) {
  sensor_msgs::CompressedImage garbage = compressed(left_.image, ros::Time::now(), "left", "png");
  garbage.data.resize(100);  // truncated: not decodable
  left_compressed_pub_.publish(garbage);
  right_compressed_pub_.publish(compressed(right_.image, garbage.header.stamp, "right", "png"));
  for (const char* format : {"png", "jpg"}) {
    const ros::Time stamp = ros::Time::now();
    left_compressed_pub_.publish(compressed(left_.image, stamp, "left", format));
    right_compressed_pub_.publish(compressed(right_.image, stamp, "right", format));
    ASSERT_TRUE(answeredAtLeast(stamp)) << format << ": no correspondences";
    EXPECT_EQ(last_->header.stamp, stamp);
    EXPECT_EQ(last_->right_header.frame_id, "right");
    EXPECT_GE(last_->matches.size(), 50u) << format;
  }
  expectNoneAnswered({garbage.header.stamp});
}

TEST_F(FrameToFrameMatcherTest, MatchesEachFrameWithThePreviousOne) {
  const ros::Time first = ros::Time::now();
  frame_pub_.publish(bgrImage(left_.image, first, "camera"));
  ros::WallDuration(0.2).sleep();
  const ros::Time second = first + ros::Duration(0.5);
  frame_pub_.publish(bgrImage(right_.image, second, "camera"));
  ASSERT_TRUE(waitFor([&] { return last_ && last_->right_header.stamp == second; }));
  EXPECT_EQ(last_->header.stamp, first);  // the earlier frame is the left image
  EXPECT_GE(last_->matches.size(), 50u);
  // A frame older than the previous one is refused; the next newer one is matched.
  frame_pub_.publish(bgrImage(left_.image, first, "camera"));
  const ros::Time third = second + ros::Duration(0.5);
  frame_pub_.publish(bgrImage(left_.image, third, "camera"));
  ASSERT_TRUE(waitFor([&] { return last_->right_header.stamp == third; }));
  EXPECT_EQ(last_->header.stamp, second);
  // Each image was described once: the second frame served two pairs, and the third has the
  // first one's pixels (2 of the 4 lookups hit the cache, 2 images described).
  EXPECT_EQ(
      test::diagnosticValue(nh_, "matcher", "features reused", [](double v) { return v >= 2; }),
      2.0);
  EXPECT_EQ(test::diagnosticValue(nh_, "matcher", "images described", [](double) { return true; }),
            2.0);
}

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

/// image_pipeline's lazy subscription: the images are subscribed only while someone listens to
/// `correspondences` or `matches_image`, and given up when the last listener leaves.
TEST(LazyMatcherTest, SubscribesTheImagesOnlyWhileSomeoneListens) {
  ros::NodeHandle nh;
  ros::Publisher left = nh.advertise<sensor_msgs::Image>("left/image", 1);
  ros::Publisher right = nh.advertise<sensor_msgs::Image>("right/image", 1);
  const auto subscribed = [&] {
    return left.getNumSubscribers() > 0 && right.getNumSubscribers() > 0;
  };
  const auto unsubscribed = [&] {
    return left.getNumSubscribers() == 0 && right.getNumSubscribers() == 0;
  };
  // Long enough for a subscription that would come to come.
  EXPECT_FALSE(waitFor(subscribed, 2.0)) << "the matcher subscribed with nobody listening";
  ros::Subscriber correspondences = nh.subscribe(
      "correspondences", 1, +[](const sift_hull::CorrespondencesConstPtr&) {});
  ASSERT_TRUE(waitFor(subscribed)) << "no subscription for a correspondences listener";
  correspondences.shutdown();
  ASSERT_TRUE(waitFor(unsubscribed)) << "the images stayed subscribed after the last listener left";
  ros::Subscriber drawing = nh.subscribe(
      "matches_image", 1, +[](const sensor_msgs::ImageConstPtr&) {});
  ASSERT_TRUE(waitFor(subscribed)) << "no subscription for a matches_image listener";
  drawing.shutdown();
  EXPECT_TRUE(waitFor(unsubscribed));
}

}  // namespace
}  // namespace sift_hull

int main(int argc, char** argv) {
  ::testing::InitGoogleTest(&argc, argv);
  ros::init(argc, argv, "test_matcher_node");
  ros::NodeHandle nh;
  return RUN_ALL_TESTS();
}
