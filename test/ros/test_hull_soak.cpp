// The hull node under a campaign of hostile input, each case followed by good views: a
// surface_points message of two million points, a flood of views at 30 Hz, a camera at 1e300 m,
// a thousand ~clear_bbx boxes, ~reset with a view waiting for its pose, ~save to a FIFO. Through
// all of it a second thread calls octomap_binary every 0.1 s and every answer must come within
// 1 s; every view sent is carved or counted by reason; the hull of the good views afterwards is
// the offline one; the node's peak memory stays under 600 MB. Every wait has a deadline.

#include <diagnostic_msgs/DiagnosticArray.h>
#include <gtest/gtest.h>
#include <ros/ros.h>
#include <sys/stat.h>

#include <atomic>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <map>
#include <mutex>
#include <optional>
#include <string>
#include <thread>

#include "bad_inputs.h"
#include "diagnostics_wait.h"
#include "common/octomap_volume.h"
#include "hull_node_fixture.h"
#include "lib/conversions.h"
#include "ros_wait.h"
#include "sift_hull/BoundingBoxQuery.h"
#include "sift_hull/GetOctomap.h"
#include "sift_hull/Save.h"
#include "sift_hull/hull/hull_octomap.h"
#include "sift_hull/hull/hull_pipeline.h"
#include "sift_hull/hull/hull_view.h"
#include "common/test_data.h"

namespace sift_hull {
namespace {

using test::kDeadline_s;
using test::kViews;
using test::waitFor;
namespace rc = ros_conversions;

/// The hull node's /diagnostics values, the newest report.
class HullDiagnostics {
 public:
  explicit HullDiagnostics(ros::NodeHandle& nh)
      : sub_(nh.subscribe("/diagnostics", 20, &HullDiagnostics::onArray, this)) {}
  /// The newest report once `accept` takes it, within the deadline; empty after it.
  std::map<std::string, double> when(
      const std::function<bool(const std::map<std::string, double>&)>& accept) {
    std::map<std::string, double> values;
    waitFor([&] {
      std::lock_guard<std::mutex> lock(mutex_);
      values = values_;
      return !values.empty() && accept(values);
    });
    return accept(values) ? values : std::map<std::string, double>{};
  }

 private:
  void onArray(const diagnostic_msgs::DiagnosticArrayConstPtr& array) {
    for (const diagnostic_msgs::DiagnosticStatus& status : array->status) {
      if (status.name.find("hull") == std::string::npos) continue;
      std::lock_guard<std::mutex> lock(mutex_);
      for (const diagnostic_msgs::KeyValue& pair : status.values) {
        values_[pair.key] = std::atof(pair.value.c_str());
      }
    }
  }
  std::mutex mutex_;
  std::map<std::string, double> values_;
  ros::Subscriber sub_;
};

/// Every view the node received, carved or counted by reason (the node idle).
double accountedViews(const std::map<std::string, double>& d) {
  const char* reasons[] = {"views unpaired",    "views without pose",      "views dropped",
                           "views carved",      "views waiting for a box", "views redundant",
                           "views skipped",     "views refused",           "views bad",
                           "views discarded by ~reset"};
  double sum = 0.0;
  for (const char* reason : reasons) sum += d.count(reason) ? d.at(reason) : 0.0;
  return sum;
}

class HullSoakTest : public test::HullNodeTest {
 protected:
  void SetUp() override {
    HullNodeTest::SetUp();
    ASSERT_TRUE(waitFor([&] { return (pid_ = bad_inputs::nodePid("/hull")) > 0; }));
    ASSERT_TRUE(ros::service::waitForService("/octomap_binary", ros::Duration(kDeadline_s)));
    prober_ = std::thread([this] { probe(); });
  }
  void TearDown() override {
    stop_ = true;
    if (prober_.joinable()) prober_.join();
    EXPECT_LT(slowest_s_.load(), 1.0) << "octomap_binary answered after " << slowest_s_ << " s";
    EXPECT_GT(probes_.load(), 0u);
    EXPECT_TRUE(bad_inputs::processRunning(pid_)) << "the hull node died";
    const long peak_kib = bad_inputs::peakRssKiB(pid_);
    std::printf("hull node peak RSS %ld KiB, slowest octomap_binary %.3f s of %zu calls\n",
                peak_kib, slowest_s_.load(), probes_.load());
    EXPECT_GT(peak_kib, 0);
    EXPECT_LT(peak_kib, 600 * 1024) << "peak RSS " << peak_kib / 1024 << " MB";
  }

  /// octomap_binary every 0.1 s: how long the slowest answer took (a refusal is an answer).
  void probe() {
    ros::NodeHandle nh;
    ros::ServiceClient client = nh.serviceClient<sift_hull::GetOctomap>("/octomap_binary", true);
    while (!stop_) {
      sift_hull::GetOctomap call;
      const ros::WallTime start = ros::WallTime::now();
      if (!client.isValid()) client = nh.serviceClient<sift_hull::GetOctomap>("/octomap_binary", true);
      client.call(call);
      const double took = (ros::WallTime::now() - start).toSec();
      if (took > slowest_s_) slowest_s_ = took;
      ++probes_;
      ros::WallDuration(0.1).sleep();
    }
  }

  /// Carves every view and waits for its map.
  void carveAll() {
    const ros::Time last = publishAllViews();
    ASSERT_TRUE(octomapStampedAtLeast(last)) << "no octomap for the last view";
  }

  /// The good views again, after ~reset: their hull is the offline one.
  void expectTheOfflineHull() {
    resetHull();
    carveAll();
    HullConfig config;
    config.max_depth = 6;
    const HullResult offline = buildHull(hullInputOf(views_), config);
    const double offline_m3 =
        test::occupiedVolume(rc::octomapMessage(*toOctomap(offline.hull), {}));
    EXPECT_NEAR(test::occupiedVolume(*last_octomap_), offline_m3, 0.02 * offline_m3);
  }

  sift_hull::SurfacePoints pairMessage(const PinholeCamera& left, const PinholeCamera& right,
                                       size_t points) {
    std::vector<SurfacePoint> surface(points);
    for (size_t i = 0; i < points; ++i) {  // on the sphere (radius 0.8 m) seen by view 0
      const double a = 0.001 * static_cast<double>(i), b = 0.37 * static_cast<double>(i);
      surface[i].X_W = 0.8 * Eigen::Vector3d(std::cos(a) * std::cos(b), std::sin(a) * std::cos(b),
                                             std::sin(b));
    }
    std_msgs::Header header;
    header.frame_id = "world";
    header.stamp = ros::Time::now();
    return rc::surfacePointsMessage(header, left, right, surface);
  }

  int pid_ = -1;
  std::thread prober_;
  std::atomic<bool> stop_{false};
  std::atomic<double> slowest_s_{0.0};
  std::atomic<size_t> probes_{0};
};

TEST_F(HullSoakTest, TwoMillionSurfacePointsAreSubsampledAndTheNodeAnswers) {
  ASSERT_NO_FATAL_FAILURE(carveAll());
  ros::Publisher points = nh_.advertise<sift_hull::SurfacePoints>("surface_points", 2);
  ASSERT_TRUE(waitFor([&] { return points.getNumSubscribers() > 0; }));
  const PinholeCamera& left = views_[0].view.camera;
  points.publish(pairMessage(left, views_[1].view.camera, 2000000));
  HullDiagnostics diagnostics(nh_);
  const auto d = diagnostics.when([](const std::map<std::string, double>& v) {
    return v.count("surface_points merged") && v.at("surface_points merged") >= 1;
  });
  ASSERT_FALSE(d.empty()) << "the pair was not merged";
  EXPECT_GE(d.at("surface points subsampled away"), 2000000 - 20000);
  ASSERT_NO_FATAL_FAILURE(expectTheOfflineHull());
}

TEST_F(HullSoakTest, AFloodOfViewsIsCarvedOrCountedByReason) {
  HullDiagnostics diagnostics(nh_);
  const auto before = diagnostics.when([](const std::map<std::string, double>&) { return true; });
  ASSERT_FALSE(before.empty());
  const long idle_kib = bad_inputs::rssKiB(pid_);
  const int kFlood = 111;
  ros::Time last;
  for (int i = 0; i < kFlood; ++i) {  // 30 Hz, the fixture's 0.05 s sleep included
    last = publishView(i % kViews, {}, bad_inputs::freshStamp());
  }
  const auto after = diagnostics.when([&](const std::map<std::string, double>& v) {
    return v.at("silhouettes received") >= before.at("silhouettes received") + kFlood &&
           v.at("views waiting") == 0 &&
           accountedViews(v) - accountedViews(before) >= kFlood;
  });
  ASSERT_FALSE(after.empty()) << "the flood's views are not all accounted for";
  EXPECT_EQ(after.at("silhouettes received") - before.at("silhouettes received"), kFlood);
  EXPECT_EQ(accountedViews(after) - accountedViews(before), kFlood);
  // The flood's memory given back: 10 s after it, within 25 % of the idle level before it.
  ros::WallDuration(10.0).sleep();
  const long after_kib = bad_inputs::rssKiB(pid_);
  std::printf("hull node RSS: idle %ld KiB, 10 s after the flood %ld KiB\n", idle_kib, after_kib);
  EXPECT_GT(idle_kib, 0);
  EXPECT_LE(after_kib, idle_kib + idle_kib / 4) << "RSS " << after_kib << " KiB, idle " << idle_kib;
  ASSERT_NO_FATAL_FAILURE(expectTheOfflineHull());
}

TEST_F(HullSoakTest, ACameraAt1e300IsRefusedAndTheNextPairStillCarves) {
  ASSERT_NO_FATAL_FAILURE(carveAll());
  ros::Publisher points = nh_.advertise<sift_hull::SurfacePoints>("surface_points", 2);
  ASSERT_TRUE(waitFor([&] { return points.getNumSubscribers() > 0; }));
  const PinholeCamera& left = views_[0].view.camera;
  const PinholeCamera far =
      PinholeCamera::fromCentre(left.K(), left.R(), Eigen::Vector3d(0.0, 0.0, 1e300));
  points.publish(pairMessage(left, far, 1000));
  HullDiagnostics diagnostics(nh_);
  EXPECT_FALSE(diagnostics
                   .when([](const std::map<std::string, double>& v) {
                     return v.count("surface_points refused (far camera)") &&
                            v.at("surface_points refused (far camera)") >= 1;
                   })
                   .empty());
  EXPECT_TRUE(loggedError({"surface points refused", "max_distance_cube_edges"}));
  points.publish(pairMessage(left, views_[1].view.camera, 20000));
  EXPECT_FALSE(diagnostics
                   .when([](const std::map<std::string, double>& v) {
                     return v.at("surface_points merged") >= 1 && v.at("free voxels") > 0;
                   })
                   .empty())
      << "the good pair after the far one did not carve";
  ASSERT_NO_FATAL_FAILURE(expectTheOfflineHull());
}

TEST_F(HullSoakTest, AThousandBoxesAreClearedIntoTheMapEachAtOnce) {
  ASSERT_NO_FATAL_FAILURE(carveAll());
  sift_hull::BoundingBoxQuery clear;
  for (int i = 0; i < 1000; ++i) {  // small boxes along the sphere's axis, then one at its centre
    const double z = -0.5 + 0.001 * i;
    clear.request.min.x = clear.request.min.y = -0.02;
    clear.request.max.x = clear.request.max.y = 0.02;
    clear.request.min.z = z;
    clear.request.max.z = z + 0.01;
    const ros::WallTime start = ros::WallTime::now();
    ASSERT_TRUE(ros::service::call("/hull/clear_bbx", clear)) << "box " << i;
    ASSERT_LT((ros::WallTime::now() - start).toSec(), 1.0) << "box " << i;
  }
  const ros::Time cleared_stamp = last_octomap_->header.stamp;
  // A new view (view 0 once more, later): the boxes stay in the map it gives.
  publishView(0);
  sift_hull::GetOctomap map;
  ASSERT_TRUE(ros::service::call("/octomap_binary", map));
  const std::unique_ptr<octomap::OcTree> tree = test::binaryTree(map.response.map);
  ASSERT_NE(tree, nullptr);
  EXPECT_GE(map.response.map.header.stamp, cleared_stamp);
  const octomap::OcTreeNode* centre = tree->search(0.0, 0.0, 0.0);
  ASSERT_NE(centre, nullptr);
  EXPECT_FALSE(tree->isNodeOccupied(centre)) << "the centre was cleared";
  const octomap::OcTreeNode* side = tree->search(0.0, 0.5, 0.0);
  ASSERT_NE(side, nullptr);
  EXPECT_TRUE(tree->isNodeOccupied(side)) << "beside the boxes the sphere stays";
  ASSERT_NO_FATAL_FAILURE(expectTheOfflineHull());
}

TEST_F(HullSoakTest, ResetDropsAViewWaitingForItsPose) {
  HullDiagnostics diagnostics(nh_);
  const auto before = diagnostics.when([](const std::map<std::string, double>&) { return true; });
  ASSERT_FALSE(before.empty());
  // A view in a frame tf does not know yet, then ~reset, then its pose.
  publishView(0, [](sensor_msgs::Image* image, sensor_msgs::CameraInfo* info) {
    image->header.frame_id = info->header.frame_id = "camera_late";
  });
  std_srvs::Empty reset;
  ASSERT_TRUE(ros::service::call("/hull/reset", reset));
  tf_.sendTransform(rc::cameraPoseMessage(views_[0].view.camera, "world", "camera_late", {}));
  const auto after = diagnostics.when([&](const std::map<std::string, double>& v) {
    return v.at("views discarded by ~reset") >= before.at("views discarded by ~reset") + 1;
  });
  ASSERT_FALSE(after.empty()) << "the waiting view was not discarded";
  ros::WallDuration(0.5).sleep();
  const auto later = diagnostics.when([](const std::map<std::string, double>&) { return true; });
  EXPECT_EQ(later.at("views carved"), before.at("views carved")) << "it was carved after all";
  EXPECT_EQ(later.at("views waiting for a box"), 0) << "it waits in the new hull";
  ASSERT_NO_FATAL_FAILURE(expectTheOfflineHull());
}

TEST_F(HullSoakTest, SaveRefusesAFifoAtOnceAndWritesARegularFile) {
  ASSERT_NO_FATAL_FAILURE(carveAll());
  const std::string dir = test::temporaryDirectory();
  ASSERT_EQ(::mkfifo((dir + "/pipe.bt").c_str(), 0600), 0);
  sift_hull::Save save;
  save.request.path = dir + "/pipe";
  const ros::WallTime start = ros::WallTime::now();
  ASSERT_TRUE(ros::service::call("/hull/save", save));
  EXPECT_LT((ros::WallTime::now() - start).toSec(), 1.0);
  EXPECT_FALSE(save.response.success);
  EXPECT_NE(save.response.message.find("not a regular file"), std::string::npos)
      << save.response.message;
  save.request.path = std::string("/tmp/a\0b", 8);
  ASSERT_TRUE(ros::service::call("/hull/save", save));
  EXPECT_FALSE(save.response.success);
  EXPECT_NE(save.response.message.find("NUL"), std::string::npos) << save.response.message;
  save.request.path = dir + "/hull";
  ASSERT_TRUE(ros::service::call("/hull/save", save));
  EXPECT_TRUE(save.response.success) << save.response.message;
  octomap::OcTree saved(0.1);
  ASSERT_TRUE(saved.readBinary(dir + "/hull.bt"));
  const double published_m3 = test::occupiedVolume(*last_octomap_);
  EXPECT_GT(published_m3, 0.0);
  // The same leaves: within half the smallest voxel (the two differ only in rounding).
  EXPECT_NEAR(test::occupiedVolume(saved), published_m3, 0.5 * std::pow(saved.getResolution(), 3));
  // The box the hull was carved in: in the file's header, as /diagnostics gives it; the offline
  // hull in that box (sift_hull hull --box hull.bt) is the node's to the voxel.
  const std::optional<Box3d> box = readCarvingBox(dir + "/hull.bt");
  ASSERT_TRUE(box.has_value()) << "no carving_box line in the saved file";
  EXPECT_EQ(test::diagnosticText(nh_, "hull", "carving box (m)",
                                 [](const std::string& text) { return !text.empty(); }),
            boxText(*box));
  HullConfig config;
  config.max_depth = 6;
  const HullResult offline = buildHull(hullInputOf(views_), config, box);
  const double offline_m3 = test::occupiedVolume(rc::octomapMessage(*toOctomap(offline.hull), {}));
  EXPECT_NEAR(published_m3, offline_m3, 0.5 * std::pow(saved.getResolution(), 3));
  ASSERT_NO_FATAL_FAILURE(expectTheOfflineHull());
}

}  // namespace
}  // namespace sift_hull

int main(int argc, char** argv) {
  testing::InitGoogleTest(&argc, argv);
  ros::init(argc, argv, "test_hull_soak");
  ros::NodeHandle nh;
  return RUN_ALL_TESTS();
}
