// Hostile input for hull_node and matcher_node (test/bad_inputs.test). Each bad message must
// (a) give a specific error from that node on /rosout, (b) leave the node running (the same
// process answers its XML-RPC getPid), and (c) not keep a good message sent after it from being
// processed (octomap_binary / correspondences). Floods must leave the node's resident memory
// flat. Every wait has a deadline.
//
// This file: hull_node.

#include "bad_inputs.h"
#include "hull_node_fixture.h"

namespace sift_hull {
namespace bad_inputs {
namespace {

// ---- hull_node -------------------------------------------------------------------------------

struct ViewData {
  std::string frame;
  PinholeCamera camera;
  cv::Mat mask;
};

using test::kViews;
constexpr double kSphereRadius_m = 0.8;

/// The camera turned by `degrees` about the world's z axis through the origin (still looking at
/// the sphere): a viewpoint none of the scene's views has.
PinholeCamera turnedCamera(const PinholeCamera& camera, double degrees) {
  const Eigen::Matrix3d turn =
      Eigen::AngleAxisd(degrees * M_PI / 180.0, Eigen::Vector3d::UnitZ()).toRotationMatrix();
  return PinholeCamera::fromCentre(camera.K(), camera.R() * turn.transpose(),
                                   turn * camera.centre());
}

/// A camera at twice view 0's distance on its ray, looking away from the sphere: its cone meets no
/// other view's.
PinholeCamera lookingAway(const PinholeCamera& camera) {
  const Eigen::Vector3d centre = 2.0 * camera.centre();
  const Eigen::Vector3d z = camera.centre().normalized();
  const Eigen::Vector3d x = z.cross(Eigen::Vector3d::UnitZ()).normalized();
  const Eigen::Vector3d y = z.cross(x);
  Eigen::Matrix3d R;
  R << x.transpose(), y.transpose(), z.transpose();
  return PinholeCamera::fromCentre(camera.K(), R, centre);
}

struct HullData {
  std::vector<ViewData> good;   // the 8 views of the sphere scene
  std::vector<ViewData> fresh;  // more true views of the sphere, from other viewpoints
  ViewData away;                // a small blob in a camera looking away
  ViewData nan_pose, far_pose;  // view 0's silhouette in frames whose pose is NaN / 1e39 away
  std::unique_ptr<tf2_ros::StaticTransformBroadcaster> tf;
};

HullData& hullData() {
  static HullData data = [] {
    HullData d;
    const std::vector<RenderedView> views = test::sphereViews();
    for (int v = 0; v < kViews; ++v) {
      d.good.push_back({test::frameOf(v), views[v].view.camera, views[v].mask});
    }
    const Shape shape = Shape::byName("sphere");
    const cv::Size size = views[0].mask.size();  // sphereViews: 320x240, the default seed
    for (double degrees : {20.0, 45.0}) {
      for (int v = 0; v < kViews; ++v) {
        CalibratedView view;
        view.camera = turnedCamera(views[v].view.camera, degrees);
        const RenderedView rendered = renderView(shape, view, size, SceneConfig().seed);
        d.fresh.push_back({"fresh_" + std::to_string(d.fresh.size()), view.camera, rendered.mask});
      }
    }
    cv::Mat blob = cv::Mat::zeros(size, CV_8UC1);
    blob(cv::Rect(size.width / 2 - 4, size.height / 2 - 4, 9, 9)).setTo(255);
    d.away = {"camera_away", lookingAway(views[0].view.camera), blob};
    d.nan_pose = {"camera_nan", views[0].view.camera, views[0].mask};
    d.far_pose = {"camera_far", views[0].view.camera, views[0].mask};

    std::vector<geometry_msgs::TransformStamped> poses;
    for (const std::vector<ViewData>* list : {&d.good, &d.fresh}) {
      for (const ViewData& view : *list) {
        poses.push_back(ros_conversions::cameraPoseMessage(view.camera, "world", view.frame, {}));
      }
    }
    poses.push_back(ros_conversions::cameraPoseMessage(d.away.camera, "world", d.away.frame, {}));
    // Not a number: tf refuses it, so the frame never gets a pose.
    poses.push_back(
        ros_conversions::cameraPoseMessage(d.nan_pose.camera, "world", "camera_nan", {}));
    poses.back().transform.translation.x = std::nan("");
    // Huge but finite.
    poses.push_back(
        ros_conversions::cameraPoseMessage(d.far_pose.camera, "world", "camera_far", {}));
    poses.back().transform.translation.x = 1e39;
    d.tf = std::make_unique<tf2_ros::StaticTransformBroadcaster>();
    d.tf->sendTransform(poses);
    return d;
  }();
  return data;
}

using Change = std::function<void(sensor_msgs::Image*, sensor_msgs::CameraInfo*)>;

class HullBadInputTest : public NodeUnderTest {
 protected:
  void SetUp() override {
    data_ = &hullData();
    silhouette_pub_ = nh_.advertise<sensor_msgs::Image>("silhouette", kFlood + 10);
    info_pub_ = nh_.advertise<sensor_msgs::CameraInfo>("camera_info", kFlood + 10);
    octomap_sub_ = nh_.subscribe("octomap_binary", 20, &HullBadInputTest::onOctomap, this);
    ASSERT_TRUE(waitFor([&] {
      return silhouette_pub_.getNumSubscribers() > 0 && info_pub_.getNumSubscribers() > 0 &&
             octomap_sub_.getNumPublishers() > 0;
    })) << "the hull node did not connect";
    ASSERT_NO_FATAL_FAILURE(findNode("/hull"));
  }

  void onOctomap(const sift_hull::OctomapConstPtr& message) { last_octomap_ = message; }

  /// Publishes a view (camera_info from its camera, sized like its mask) with `stamp` (default: a
  /// fresh one); `change` may spoil the messages first. Pauses a little after unless told not to.
  ros::Time publishView(const ViewData& view, const Change& change = {}, ros::Time stamp = {},
                        bool pause = true) {
    if (stamp.isZero()) stamp = freshStamp();
    std_msgs::Header header;
    header.stamp = stamp;
    header.frame_id = view.frame;
    sensor_msgs::Image image = ros_conversions::imageMessage(view.mask, header);
    sensor_msgs::CameraInfo info =
        ros_conversions::cameraInfoMessage(view.camera, view.mask.size(), header);
    if (change) change(&image, &info);
    info_pub_.publish(info);
    silhouette_pub_.publish(image);
    if (pause) ros::WallDuration(0.05).sleep();
    return stamp;
  }

  bool octomapStampedAtLeast(const ros::Time& stamp) {
    return waitFor([&] { return last_octomap_ && last_octomap_->header.stamp >= stamp; });
  }

  void resetHull() {
    std_srvs::Empty reset;
    ASSERT_TRUE(ros::service::waitForService("/hull/reset", ros::Duration(kDeadline_s)));
    const ros::Time before = ros::Time::now();
    ASSERT_TRUE(ros::service::call("/hull/reset", reset));
    ASSERT_TRUE(waitFor([&] {
      return last_octomap_ && last_octomap_->header.stamp >= before &&
             occupiedVolume(*last_octomap_) == 0.0;
    })) << "no empty octomap after ~reset";
  }

  /// ~reset, then the 8 good views: the hull of the sphere. Returns its occupied volume.
  double buildHull() {
    resetHull();
    if (::testing::Test::HasFatalFailure()) return 0.0;
    ros::Time last;
    for (const ViewData& view : data_->good) last = publishView(view);
    EXPECT_TRUE(octomapStampedAtLeast(last)) << "no octomap for the 8 good views";
    if (!last_octomap_) return 0.0;
    const double volume = occupiedVolume(*last_octomap_);
    const double sphere_m3 = 4.0 / 3.0 * M_PI * std::pow(kSphereRadius_m, 3);
    EXPECT_NEAR(volume, sphere_m3, 0.3 * sphere_m3);
    return volume;
  }

  /// A true view from a viewpoint the hull lacks is carved (octomap stamped with it), and the
  /// node is the same process.
  void expectGoodViewCarved() {
    ASSERT_LT(next_fresh_, data_->fresh.size());
    const ros::Time stamp = publishView(data_->fresh[next_fresh_++]);
    ASSERT_TRUE(octomapStampedAtLeast(stamp))
        << "a good view after bad input was not carved; the hull node logged:\n"
        << rosout().linesOf("/hull", 0);
    expectAlive();
  }

  HullData* data_ = nullptr;
  size_t next_fresh_ = 0;
  ros::Publisher silhouette_pub_, info_pub_;
  ros::Subscriber octomap_sub_;
  sift_hull::OctomapConstPtr last_octomap_;
};

// 6. A silhouette whose height x step wraps 32 bits.
TEST_F(HullBadInputTest, WrapStepSilhouetteIsRefused) {
  buildHull();
  ASSERT_FALSE(HasFatalFailure());
  const size_t since = rosout().mark();
  publishView(data_->good[0], [](sensor_msgs::Image* image, sensor_msgs::CameraInfo*) {
    *image = wrapStepImage(image->header.stamp, image->header.frame_id);
  });
  EXPECT_TRUE(
      loggedError("/hull", {"does not hold", std::to_string(kWrapStep), "camera_0"}, since));
  expectAlive();
  expectGoodViewCarved();
}

// 7. Two bad camera_infos right after each other: different reasons, both reported.
TEST_F(HullBadInputTest, ZeroKAndNonFiniteKAreBothReported) {
  buildHull();
  ASSERT_FALSE(HasFatalFailure());
  const size_t since = rosout().mark();
  publishView(
      data_->good[2], [](sensor_msgs::Image*, sensor_msgs::CameraInfo* info) { info->K.fill(0.0); },
      {}, false);
  publishView(
      data_->good[3],
      [](sensor_msgs::Image*, sensor_msgs::CameraInfo* info) { info->K[4] = std::nan(""); }, {},
      false);
  EXPECT_TRUE(loggedError("/hull", {"K is all zero", "camera_2"}, since));
  EXPECT_TRUE(loggedError("/hull", {"not finite", "camera_3"}, since));
  expectAlive();
  expectGoodViewCarved();
}

// 8. Poses that are NaN, missing, or finite but 1e39 m away.
TEST_F(HullBadInputTest, BadPosesAreRefused) {
  buildHull();
  ASSERT_FALSE(HasFatalFailure());
  size_t since = rosout().mark();
  publishView(data_->nan_pose);
  EXPECT_TRUE(loggedError("/hull", {"no pose of 'camera_nan'"}, since));
  expectAlive();

  since = rosout().mark();
  ViewData missing = data_->good[1];
  missing.frame = "camera_missing";
  publishView(missing);
  EXPECT_TRUE(loggedError("/hull", {"no pose of 'camera_missing'"}, since));
  expectAlive();

  since = rosout().mark();
  const ros::Time before = last_octomap_->header.stamp;
  publishView(data_->far_pose);
  EXPECT_TRUE(loggedError("/hull", {"hull: view refused: ", "camera_far"}, since));
  EXPECT_EQ(last_octomap_->header.stamp, before) << "the hull changed for a refused view";
  expectAlive();
  expectGoodViewCarved();
}

// 9. Silhouettes covering nothing or everything, once the hull exists.
TEST_F(HullBadInputTest, EmptyAndFullSilhouettesAreRefused) {
  const double volume = buildHull();
  ASSERT_FALSE(HasFatalFailure());
  ASSERT_GT(volume, 0.0);
  size_t since = rosout().mark();
  ros::Time before = last_octomap_->header.stamp;
  publishView(data_->good[1], [](sensor_msgs::Image* image, sensor_msgs::CameraInfo*) {
    std::fill(image->data.begin(), image->data.end(), 0);
  });
  EXPECT_TRUE(loggedError("/hull", {"covers no pixel", "camera_1"}, since));
  ros::WallDuration(0.5).sleep();
  ros::spinOnce();
  EXPECT_EQ(last_octomap_->header.stamp, before) << "an all-black silhouette was published";
  EXPECT_EQ(occupiedVolume(*last_octomap_), volume) << "an all-black silhouette changed the hull";
  expectAlive();
  expectGoodViewCarved();

  since = rosout().mark();
  before = last_octomap_->header.stamp;
  const double carved = occupiedVolume(*last_octomap_);
  publishView(data_->good[2], [](sensor_msgs::Image* image, sensor_msgs::CameraInfo*) {
    std::fill(image->data.begin(), image->data.end(), 255);
  });
  EXPECT_TRUE(loggedError("/hull", {"covers the whole image", "camera_2"}, since));
  ros::WallDuration(0.5).sleep();
  ros::spinOnce();
  EXPECT_EQ(last_octomap_->header.stamp, before) << "an all-white silhouette was published";
  EXPECT_EQ(occupiedVolume(*last_octomap_), carved) << "an all-white silhouette changed the hull";
  expectAlive();
  expectGoodViewCarved();
}

// 10. A view whose cone misses the others', sent before any good view.
TEST_F(HullBadInputTest, ViewMissingTheOthersSentFirstIsRefusedAndTheHullIsTheSame) {
  ASSERT_NO_FATAL_FAILURE(resetHull());
  const size_t since = rosout().mark();
  publishView(data_->away);
  ros::Time last;
  for (const ViewData& view : data_->good) last = publishView(view);
  ASSERT_TRUE(octomapStampedAtLeast(last))
      << "no hull from a bad view and 8 good ones; the hull node logged:\n"
      << rosout().linesOf("/hull", since);
  const double with_bad = occupiedVolume(*last_octomap_);
  EXPECT_TRUE(loggedError("/hull", {"misses the other views", "camera_away"}, since));
  expectAlive();

  const double good_only = buildHull();  // ~reset, then the 8 good views alone
  ASSERT_FALSE(HasFatalFailure());
  ASSERT_GT(good_only, 0.0);
  EXPECT_NEAR(with_bad, good_only, 0.01 * good_only);
  std::cout << "hull volume with the bad view first " << with_bad << " m^3, good views alone "
            << good_only << " m^3\n";
}

// 11. Silhouettes with duplicate stamps and stamps back in time.
TEST_F(HullBadInputTest, DuplicateAndBackwardStampsAreSurvived) {
  buildHull();
  ASSERT_FALSE(HasFatalFailure());
  const ros::Time t = freshStamp();
  // The same view twice with one stamp, then two other views sharing one stamp.
  publishView(data_->fresh[10], {}, t);
  publishView(data_->fresh[10], {}, t);
  const ros::Time shared = freshStamp();
  publishView(data_->fresh[11], {}, shared, false);
  publishView(data_->fresh[12], {}, shared);
  // Back in time.
  publishView(data_->fresh[13], {}, t - ros::Duration(5.0));
  publishView(data_->fresh[14], {}, t - ros::Duration(10.0));
  publishView(data_->good[5], {}, t - ros::Duration(20.0));
  ros::WallDuration(1.0).sleep();
  expectAlive();
  expectGoodViewCarved();
}

// 12. 200 bad silhouettes as fast as they go: the node's memory stays flat.
TEST_F(HullBadInputTest, FloodOfBadSilhouettesKeepsTheNodeAliveAndItsMemoryFlat) {
  buildHull();
  ASSERT_FALSE(HasFatalFailure());
  const long before = rss();
  const size_t since = rosout().mark();
  const cv::Size big(1280, 960);
  const cv::Mat black = cv::Mat::zeros(big, CV_8UC1);
  const cv::Mat white(big, CV_8UC1, cv::Scalar(255));
  // In turn: all black and all white at 1280x960, the wrap-style step, not mono8.
  for (int i = 0; i < kFlood; ++i) {
    ViewData view = data_->good[i % kViews];
    if (i % 4 == 0) view.mask = black;
    if (i % 4 == 1) view.mask = white;
    publishView(
        view,
        [i](sensor_msgs::Image* image, sensor_msgs::CameraInfo*) {
          if (i % 4 == 2) *image = wrapStepImage(image->header.stamp, image->header.frame_id);
          if (i % 4 == 3) image->encoding = "rgb8";
        },
        {}, false);
  }
  ros::spinOnce();
  EXPECT_TRUE(loggedError("/hull", {"covers no pixel"}, since));
  EXPECT_TRUE(loggedError("/hull", {"covers the whole image"}, since));
  EXPECT_TRUE(loggedError("/hull", {"does not hold"}, since));
  EXPECT_TRUE(loggedError("/hull", {"encoding is 'rgb8'"}, since));
  expectGoodViewCarved();
  const long after = rss();
  EXPECT_LT(after - before, kMaxRssGrowthKiB)
      << "VmRSS of the hull node grew from " << before << " KiB to " << after << " KiB";
  std::cout << "hull node VmRSS before the flood " << before << " KiB, after " << after << " KiB\n";
}

}  // namespace
}  // namespace bad_inputs
}  // namespace sift_hull
