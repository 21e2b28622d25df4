// Hostile input for hull_node and matcher_node (test/bad_inputs.test). Each bad message must
// (a) give a specific error from that node on /rosout, (b) leave the node running (the same
// process answers its XML-RPC getPid), and (c) not keep a good message sent after it from being
// processed (octomap_binary / correspondences). Floods must leave the node's resident memory
// flat. Every wait has a deadline.

#include <geometry_msgs/TransformStamped.h>
#include <gtest/gtest.h>
#include <octomap/OcTree.h>
#include <ros/master.h>
#include <ros/network.h>
#include <ros/ros.h>
#include <rosgraph_msgs/Log.h>
#include <sensor_msgs/CameraInfo.h>
#include <sensor_msgs/Image.h>
#include <std_srvs/Empty.h>
#include <tf2_ros/static_transform_broadcaster.h>
#include <xmlrpcpp/XmlRpcClient.h>

#include <cmath>
#include <fstream>
#include <functional>
#include <iostream>
#include <map>
#include <memory>
#include <mutex>
#include <sstream>
#include <string>
#include <vector>

#include "lib/conversions.h"
#include "common/octomap_volume.h"
#include "ros_wait.h"
#include "sift_hull/Correspondences.h"
#include "sift_hull/Octomap.h"
#include "sift_hull/synthetic/scene.h"
#include "sift_hull/synthetic/shape.h"
#include "sift_hull/hull/hull_pipeline.h"
#include "sift_hull/io/calibration.h"

namespace sift_hull {
namespace {

using test::kDeadline_s;
using test::occupiedVolume;
using test::waitFor;

constexpr long kMaxRssGrowthKiB = 200 * 1024;  // 200 MiB
constexpr int kFlood = 200;
/// 4 * (2^30 + 250) = 2^32 + 1000: a height x step that wraps to the 1000 bytes sent in 32 bits
/// (../shared/repro/matcher_wrap_crash.py).
constexpr uint32_t kWrapStep = (1u << 30) + 250;

// ---- /rosout ---------------------------------------------------------------------------------

struct LogLine {
  std::string node;
  int level;
  std::string msg;
};

/// Every message on /rosout since the test started.
class Rosout {
 public:
  void start(ros::NodeHandle& nh) { sub_ = nh.subscribe("/rosout", 5000, &Rosout::onLog, this); }
  const ros::Subscriber& subscriber() const { return sub_; }
  /// The number of lines so far: a mark to look from.
  size_t mark() {
    std::lock_guard<std::mutex> lock(mutex_);
    return lines_.size();
  }
  /// Whether `node` logged an error holding every one of `needles` after `since`.
  bool hasError(const std::string& node, const std::vector<std::string>& needles, size_t since) {
    std::lock_guard<std::mutex> lock(mutex_);
    for (size_t i = since; i < lines_.size(); ++i) {
      if (lines_[i].node != node || lines_[i].level < rosgraph_msgs::Log::ERROR) continue;
      bool all = true;
      for (const std::string& needle : needles)
        all = all && lines_[i].msg.find(needle) != std::string::npos;
      if (all) return true;
    }
    return false;
  }
  /// What `node` logged after `since`, one line each, for failure messages.
  std::string linesOf(const std::string& node, size_t since) {
    std::lock_guard<std::mutex> lock(mutex_);
    std::ostringstream out;
    for (size_t i = since; i < lines_.size(); ++i) {
      if (lines_[i].node != node) continue;
      out << "  [" << static_cast<int>(lines_[i].level) << "] " << lines_[i].msg << "\n";
    }
    const std::string text = out.str();
    return text.empty() ? "  (nothing)\n" : text;
  }

 private:
  void onLog(const rosgraph_msgs::LogConstPtr& log) {
    std::lock_guard<std::mutex> lock(mutex_);
    lines_.push_back({log->name, log->level, log->msg});
  }

  ros::Subscriber sub_;
  std::mutex mutex_;
  std::vector<LogLine> lines_;
};

Rosout& rosout() {
  static Rosout instance;
  return instance;
}

std::string joined(const std::vector<std::string>& needles) {
  std::string text;
  for (const std::string& needle : needles) text += (text.empty() ? "\"" : " + \"") + needle + "\"";
  return text;
}

/// Waits for an error of `node` holding every one of `needles`, logged after `since`.
::testing::AssertionResult loggedError(const std::string& node,
                                       const std::vector<std::string>& needles, size_t since) {
  if (waitFor([&] { return rosout().hasError(node, needles, since); })) {
    return ::testing::AssertionSuccess();
  }
  return ::testing::AssertionFailure()
         << "no error with " << joined(needles) << " from " << node << " on /rosout within "
         << kDeadline_s << " s; what it logged since:\n"
         << rosout().linesOf(node, since);
}

// ---- the nodes' processes --------------------------------------------------------------------

/// The process id of a ROS node, from its own XML-RPC server (getPid): -1 when the master does not
/// know it or it does not answer (it is gone).
int nodePid(const std::string& node) {
  XmlRpc::XmlRpcValue request, response, payload;
  request[0] = ros::this_node::getName();
  request[1] = node;
  if (!ros::master::execute("lookupNode", request, response, payload, false)) return -1;
  if (payload.getType() != XmlRpc::XmlRpcValue::TypeString) return -1;
  std::string host;
  uint32_t port = 0;
  if (!ros::network::splitURI(static_cast<std::string>(payload), host, port)) return -1;
  XmlRpc::XmlRpcClient client(host.c_str(), static_cast<int>(port), "/");
  XmlRpc::XmlRpcValue args, result;
  args[0] = ros::this_node::getName();
  const bool ok = client.execute("getPid", args, result);
  client.close();
  if (!ok || client.isFault() || result.getType() != XmlRpc::XmlRpcValue::TypeArray ||
      result.size() < 3 || result[0].getType() != XmlRpc::XmlRpcValue::TypeInt ||
      static_cast<int>(result[0]) != 1 || result[2].getType() != XmlRpc::XmlRpcValue::TypeInt) {
    return -1;
  }
  return static_cast<int>(result[2]);
}

/// VmRSS of a process in KiB, -1 when it cannot be read.
long rssKiB(int pid) {
  std::ifstream status("/proc/" + std::to_string(pid) + "/status");
  std::string line;
  while (std::getline(status, line)) {
    if (line.rfind("VmRSS:", 0) == 0) return std::stol(line.substr(6));
  }
  return -1;
}

/// Whether the process is there and not a zombie.
bool processRunning(int pid) {
  std::ifstream status("/proc/" + std::to_string(pid) + "/status");
  std::string line;
  while (std::getline(status, line)) {
    if (line.rfind("State:", 0) == 0) return line.find('Z') == std::string::npos;
  }
  return false;
}

/// Stamps that never repeat, so that no two test messages meet in a synchroniser by accident.
ros::Time freshStamp() {
  static ros::Time last;
  ros::Time now = ros::Time::now();
  if (now <= last) now = last + ros::Duration(0, 1000);
  last = now;
  return now;
}

sensor_msgs::Image imageMessage(const cv::Mat& image, const ros::Time& stamp,
                                const std::string& frame) {
  std_msgs::Header header;
  header.stamp = stamp;
  header.frame_id = frame;
  return ros_conversions::imageMessage(image, header);
}

/// mono8 with the wrap-style step: 4 rows 2^30 + 250 bytes apart in 1000 bytes.
sensor_msgs::Image wrapStepImage(const ros::Time& stamp, const std::string& frame) {
  sensor_msgs::Image image;
  image.header.stamp = stamp;
  image.header.frame_id = frame;
  image.encoding = "mono8";
  image.width = 250;
  image.height = 4;
  image.step = kWrapStep;
  image.data.resize(1000);
  for (size_t i = 0; i < image.data.size(); ++i) image.data[i] = static_cast<uint8_t>(i % 250);
  return image;
}

/// Common checks of the node behind a fixture.
class NodeUnderTest : public ::testing::Test {
 protected:
  void findNode(const std::string& name) {
    node_ = name;
    ASSERT_TRUE(waitFor([&] { return (pid_ = nodePid(name)) > 0; }))
        << name << " does not answer getPid";
  }
  void expectAlive() {
    const int pid = nodePid(node_);
    EXPECT_EQ(pid, pid_) << node_ << " is gone or was restarted";
    EXPECT_TRUE(processRunning(pid_)) << node_ << " (pid " << pid_ << ") is not running";
  }
  long rss() {
    const long kib = rssKiB(pid_);
    EXPECT_GT(kib, 0) << "no VmRSS for " << node_ << " (pid " << pid_ << ")";
    return kib;
  }

  ros::NodeHandle nh_;
  std::string node_;
  int pid_ = -1;
};

// ---- matcher_node ----------------------------------------------------------------------------

struct MatcherData {
  RenderedView left, right;          // 320x240
  RenderedView big_left, big_right;  // 640x480, for the flood
};

const MatcherData& matcherData() {
  static const MatcherData data = [] {
    MatcherData d;
    SceneConfig config;
    config.width_px = 320;
    config.height_px = 240;
    d.left = renderSceneView(config, 0);
    d.right = renderSceneView(config, 1);
    config.width_px = 640;
    config.height_px = 480;
    d.big_left = renderSceneView(config, 0);
    d.big_right = renderSceneView(config, 1);
    return d;
  }();
  return data;
}

class MatcherBadInputTest : public NodeUnderTest {
 protected:
  void SetUp() override {
    const MatcherData& data = matcherData();
    left_ = &data.left;
    right_ = &data.right;
    // Queues long enough that a flood reaches the node rather than being dropped here.
    left_pub_ = nh_.advertise<sensor_msgs::Image>("hostile/left/image", kFlood + 10);
    right_pub_ = nh_.advertise<sensor_msgs::Image>("hostile/right/image", kFlood + 10);
    sub_ = nh_.subscribe("correspondences", kFlood + 10, &MatcherBadInputTest::onCorrespondences,
                         this);
    ASSERT_TRUE(waitFor([&] {
      return left_pub_.getNumSubscribers() > 0 && right_pub_.getNumSubscribers() > 0 &&
             sub_.getNumPublishers() > 0;
    })) << "the matcher node did not connect";
    ASSERT_NO_FATAL_FAILURE(findNode("/matcher"));
  }

  void onCorrespondences(const sift_hull::CorrespondencesConstPtr& message) {
    answered_[message->header.stamp] = message->matches.size();
  }

  void publishPair(const sensor_msgs::Image& left, const sensor_msgs::Image& right) {
    left_pub_.publish(left);
    right_pub_.publish(right);
  }

  /// A bad pair (`left` and `right` share `stamp`): refused with an error holding `needles`.
  void expectRefused(const sensor_msgs::Image& left, const sensor_msgs::Image& right,
                     const std::vector<std::string>& needles) {
    const size_t since = rosout().mark();
    publishPair(left, right);
    bad_.push_back(left.header.stamp);
    EXPECT_TRUE(loggedError("/matcher", needles, since));
  }

  /// A good pair is matched (at least 50 matches) and the node is the same process.
  void expectGoodPairMatched() {
    const ros::Time stamp = freshStamp();
    publishPair(imageMessage(left_->image, stamp, "left"),
                imageMessage(right_->image, stamp, "right"));
    ASSERT_TRUE(waitFor([&] { return answered_.count(stamp) > 0; }))
        << "a good pair after bad input was not matched; the matcher logged:\n"
        << rosout().linesOf("/matcher", 0);
    EXPECT_GE(answered_[stamp], 50u);
    expectAlive();
  }

  /// None of the bad pairs was answered, however late.
  void expectNoBadPairAnswered() {
    ros::WallDuration(0.3).sleep();
    ros::spinOnce();
    for (const ros::Time& stamp : bad_) EXPECT_EQ(answered_.count(stamp), 0u) << stamp;
  }

  const RenderedView* left_ = nullptr;
  const RenderedView* right_ = nullptr;
  ros::Publisher left_pub_, right_pub_;
  ros::Subscriber sub_;
  std::map<ros::Time, size_t> answered_;
  std::vector<ros::Time> bad_;
};

// 1. The image whose height x step wraps 32 bits (it crashed the node).
TEST_F(MatcherBadInputTest, WrapStepImageIsRefused) {
  const ros::Time stamp = freshStamp();
  expectRefused(wrapStepImage(stamp, "left"), imageMessage(right_->image, stamp, "right"),
                {"does not hold", std::to_string(kWrapStep)});
  expectAlive();
  expectGoodPairMatched();
  expectNoBadPairAnswered();
}

// 2. Encodings that are not 8-bit colour or mono, an empty image, data shorter than step x height.
TEST_F(MatcherBadInputTest, WrongEncodingsEmptyAndTruncatedImagesAreRefused) {
  const struct {
    const char* encoding;
    uint32_t bytes_per_pixel;
  } encodings[] = {{"16UC1", 2}, {"32FC1", 4}, {"bogus", 1}};
  for (const auto& bad : encodings) {
    const ros::Time stamp = freshStamp();
    sensor_msgs::Image image = imageMessage(left_->image, stamp, "left");
    image.encoding = bad.encoding;
    image.step = image.width * bad.bytes_per_pixel;
    image.data.assign(static_cast<size_t>(image.step) * image.height, 128);
    expectRefused(image, imageMessage(right_->image, stamp, "right"),
                  {"encoding '" + std::string(bad.encoding) + "'"});
    expectAlive();
  }
  {
    const ros::Time stamp = freshStamp();
    sensor_msgs::Image empty = imageMessage(left_->image, stamp, "left");
    empty.width = empty.height = empty.step = 0;
    empty.data.clear();
    expectRefused(empty, imageMessage(right_->image, stamp, "right"), {"the image is empty (0x0)"});
    expectAlive();
  }
  {
    const ros::Time stamp = freshStamp();
    sensor_msgs::Image truncated = imageMessage(right_->image, stamp, "right");
    truncated.data.resize(static_cast<size_t>(truncated.step) * (truncated.height - 1));
    expectRefused(imageMessage(left_->image, stamp, "left"), truncated,
                  {"does not hold", std::to_string(truncated.data.size()) + " bytes"});
    expectAlive();
  }
  expectGoodPairMatched();
  expectNoBadPairAnswered();
}

// 3. A pair over ~max_image_pixels (default 25 megapixels): refused on arrival from the headers.
TEST_F(MatcherBadInputTest, ImagesOverMaxImagePixelsAreRefused) {
  const ros::Time stamp = freshStamp();
  sensor_msgs::Image big;
  big.header.stamp = stamp;
  big.header.frame_id = "left";
  big.encoding = "mono8";
  big.width = 6000;
  big.height = 5000;
  big.step = big.width;
  big.data.assign(static_cast<size_t>(big.step) * big.height, 0);
  big.data[12345] = 255;
  sensor_msgs::Image big_right = big;
  big_right.header.frame_id = "right";
  expectRefused(big, big_right, {"max_image_pixels", "6000x5000"});
  expectAlive();
  expectGoodPairMatched();
  expectNoBadPairAnswered();
}

// 4. 200 pairs of 640x480 as fast as they go: bounded queues keep the memory flat.
TEST_F(MatcherBadInputTest, FloodOfPairsKeepsTheNodeAliveAndItsMemoryFlat) {
  ASSERT_NO_FATAL_FAILURE(expectGoodPairMatched());  // warm: the first allocations are made
  const long before = rss();
  const MatcherData& data = matcherData();
  const sensor_msgs::Image left = imageMessage(data.big_left.image, {}, "left");
  const sensor_msgs::Image right = imageMessage(data.big_right.image, {}, "right");
  for (int i = 0; i < kFlood; ++i) {
    sensor_msgs::Image l = left, r = right;
    l.header.stamp = r.header.stamp = freshStamp();
    publishPair(l, r);
  }
  ros::spinOnce();
  expectGoodPairMatched();
  const long after = rss();
  EXPECT_LT(after - before, kMaxRssGrowthKiB)
      << "VmRSS of the matcher grew from " << before << " KiB to " << after << " KiB";
  std::cout << "matcher VmRSS before the flood " << before << " KiB, after " << after << " KiB, "
            << answered_.size() << " pairs answered in all\n";
}

// 5. Exact sync fed duplicate stamps and stamps back in time.
TEST_F(MatcherBadInputTest, DuplicateAndBackwardStampsAreSurvived) {
  const ros::Time t = freshStamp();
  const sensor_msgs::Image left = imageMessage(left_->image, t, "left");
  const sensor_msgs::Image right = imageMessage(right_->image, t, "right");
  publishPair(left, right);
  ASSERT_TRUE(waitFor([&] { return answered_.count(t) > 0; })) << "the first pair was not matched";
  publishPair(left, right);  // the same stamps again
  publishPair(left, right);
  for (double back_s : {1.0, 2.0, 0.5}) {  // back in time
    sensor_msgs::Image l = left, r = right;
    l.header.stamp = r.header.stamp = t - ros::Duration(back_s);
    publishPair(l, r);
  }
  {
    // One slot filled twice on the left, then once on the right; a right image twice alone.
    sensor_msgs::Image l = left, r = right;
    l.header.stamp = r.header.stamp = t - ros::Duration(3.0);
    left_pub_.publish(l);
    left_pub_.publish(l);
    right_pub_.publish(r);
    r.header.stamp = t - ros::Duration(4.0);
    right_pub_.publish(r);
    right_pub_.publish(r);
  }
  ros::WallDuration(1.0).sleep();
  expectAlive();
  expectGoodPairMatched();
}

// ---- hull_node -------------------------------------------------------------------------------

struct ViewData {
  std::string frame;
  PinholeCamera camera;
  cv::Mat mask;
};

constexpr int kViews = 8;
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
    SceneConfig config;
    config.shape = "sphere";
    config.views = kViews;
    config.layout = "sphere";
    config.width_px = 320;
    config.height_px = 240;
    const std::vector<RenderedView> views = renderScene(config);
    for (int v = 0; v < kViews; ++v) {
      d.good.push_back({"camera_" + std::to_string(v), views[v].view.camera, views[v].mask});
    }
    const Shape shape = Shape::byName("sphere");
    const cv::Size size(config.width_px, config.height_px);
    for (double degrees : {20.0, 45.0}) {
      for (int v = 0; v < kViews; ++v) {
        CalibratedView view{"", turnedCamera(views[v].view.camera, degrees), ""};
        const RenderedView rendered = renderView(shape, view, size, config.seed);
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
}  // namespace sift_hull

int main(int argc, char** argv) {
  ::testing::InitGoogleTest(&argc, argv);
  ros::init(argc, argv, "test_bad_inputs");
  ros::NodeHandle nh;  // keeps the node alive through the tests
  sift_hull::rosout().start(nh);
  // Connected to every publisher of /rosout: this process, the hull and the matcher node (the
  // fixtures then wait for each node's topics).
  if (!sift_hull::test::waitFor(
          [] { return sift_hull::rosout().subscriber().getNumPublishers() >= 3; })) {
    std::cerr << "warning: /rosout has " << sift_hull::rosout().subscriber().getNumPublishers()
              << " publishers connected, expected 3 (this test, hull, matcher)\n";
  }
  return RUN_ALL_TESTS();
}
