// The nodelets' life in a nodelet manager, loaded and unloaded through its services: a fatal
// configuration fails the load, says which parameter, and leaves nothing loaded; a nodelet
// unloaded while one of its callbacks runs and loaded again under its name has its services.
// Every wait has a deadline.

#include <gtest/gtest.h>
#include <nodelet/NodeletList.h>
#include <nodelet/NodeletLoad.h>
#include <nodelet/NodeletUnload.h>
#include <ros/ros.h>
#include <rosgraph_msgs/Log.h>
#include <std_srvs/Empty.h>

#include <algorithm>
#include <atomic>
#include <mutex>
#include <string>
#include <thread>
#include <vector>

#include "ros_wait.h"
#include "sift_hull/SurfacePoints.h"

namespace sift_hull {
namespace {

using test::kDeadline_s;
using test::waitFor;

/// The hull node's services, as a nodelet named /hull in the root namespace.
const std::vector<std::string> kHullServices = {"/hull/reset", "/hull/save", "/hull/clear_bbx",
                                                "/octomap_binary", "/octomap_full"};

bool loadNodelet(const std::string& name, const std::string& type) {
  nodelet::NodeletLoad load;
  load.request.name = name;
  load.request.type = type;
  return ros::service::call("/manager/load_nodelet", load) && load.response.success;
}

bool unloadNodelet(const std::string& name) {
  nodelet::NodeletUnload unload;
  unload.request.name = name;
  return ros::service::call("/manager/unload_nodelet", unload) && unload.response.success;
}

bool isLoaded(const std::string& name) {
  nodelet::NodeletList list;
  if (!ros::service::call("/manager/list", list)) return false;
  const std::vector<std::string>& loaded = list.response.nodelets;
  return std::find(loaded.begin(), loaded.end(), name) != loaded.end();
}

bool allExist(const std::vector<std::string>& services) {
  return std::all_of(services.begin(), services.end(),
                     [](const std::string& s) { return ros::service::exists(s, false); });
}

class NodeletLifecycleTest : public ::testing::Test {
 protected:
  void SetUp() override {
    rosout_sub_ = nh_.subscribe("/rosout", 1000, &NodeletLifecycleTest::onLog, this);
    ASSERT_TRUE(ros::service::waitForService("/manager/load_nodelet", ros::Duration(kDeadline_s)));
    // The manager's errors reach this test only once its /rosout link to the test is up, which
    // can be after the first load: until one of them arrives, unload a nodelet it does not have,
    // which it logs as an error naming it.
    ASSERT_TRUE(waitFor([&] {
      unloadNodelet("/never_loaded");
      return managerLogged({"/never_loaded"}, 0.2);
    })) << "no error of the manager reached this test on /rosout";
  }

  /// Whether the manager logged an error or worse holding every one of `parts` within `seconds`.
  bool managerLogged(const std::vector<std::string>& parts, double seconds = kDeadline_s) {
    return waitFor(
        [&] {
          std::lock_guard<std::mutex> lock(mutex_);
          return std::any_of(errors_.begin(), errors_.end(), [&](const std::string& line) {
            return std::all_of(parts.begin(), parts.end(), [&](const std::string& part) {
              return line.find(part) != std::string::npos;
            });
          });
        },
        seconds);
  }

  void onLog(const rosgraph_msgs::LogConstPtr& log) {
    std::lock_guard<std::mutex> lock(mutex_);
    if (log->name == "/manager" && log->level >= rosgraph_msgs::Log::ERROR) {
      errors_.push_back(log->msg);
    }
  }

  ros::NodeHandle nh_;
  ros::Subscriber rosout_sub_;
  std::mutex mutex_;
  std::vector<std::string> errors_;
};

TEST_F(NodeletLifecycleTest, AFatalConfigurationFailsTheLoadAndNamesTheParameter) {
  ros::param::set("/bad_matcher/ratio", 7.0);  // outside (0, 1]
  EXPECT_FALSE(loadNodelet("/bad_matcher", "sift_hull/matcher"));
  EXPECT_FALSE(isLoaded("/bad_matcher")) << "the manager kept the nodelet that failed";
  EXPECT_TRUE(managerLogged({"/bad_matcher", "~ratio"})) << "no error naming ~ratio on /rosout";
}

TEST_F(NodeletLifecycleTest, ANodeletLoadedAgainWhileItsOldInstanceIsBusyHasItsServices) {
  ASSERT_TRUE(loadNodelet("/hull", "sift_hull/hull"));
  ASSERT_TRUE(waitFor([] { return allExist(kHullServices); }));
  // Surface points in a frame tf does not know: each keeps the hull's callback waiting for its
  // pose (up to 0.5 s), so that the unload below finds a callback of the old instance running.
  ros::Publisher points = nh_.advertise<sift_hull::SurfacePoints>("surface_points", 10);
  ASSERT_TRUE(waitFor([&] { return points.getNumSubscribers() > 0; }));
  std::atomic<bool> stop{false};
  std::thread feed([&] {
    sift_hull::SurfacePoints message;
    message.header.frame_id = "nowhere";
    while (!stop) {
      message.header.stamp = ros::Time::now();
      points.publish(message);
      ros::WallDuration(0.05).sleep();
    }
  });
  ros::WallDuration(0.3).sleep();
  const bool unloaded = unloadNodelet("/hull");
  const bool loaded = loadNodelet("/hull", "sift_hull/hull");
  stop = true;
  feed.join();
  ASSERT_TRUE(unloaded);
  ASSERT_TRUE(loaded);
  // Long enough for an old instance still alive to have gone, with the services it held.
  ros::WallDuration(2.0).sleep();
  for (const std::string& service : kHullServices) {
    EXPECT_TRUE(ros::service::exists(service, false)) << service << " lost on reloading";
  }
  std_srvs::Empty reset;
  EXPECT_TRUE(ros::service::call("/hull/reset", reset));
  EXPECT_FALSE(managerLogged({"already advertised"}, 0.5));
}

}  // namespace
}  // namespace sift_hull

int main(int argc, char** argv) {
  ::testing::InitGoogleTest(&argc, argv);
  ros::init(argc, argv, "test_nodelet_lifecycle");
  ros::NodeHandle nh;
  return RUN_ALL_TESTS();
}
