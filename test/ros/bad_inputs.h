#pragma once
// What the hostile-input tests of both nodes share (test_bad_inputs_matcher.cpp,
// test_bad_inputs_hull.cpp, one binary under test/ros/bad_inputs.test): /rosout, the nodes'
// processes, a fixture per node.

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

#include "common/octomap_volume.h"
#include "lib/conversions.h"
#include "ros_wait.h"
#include "sift_hull/Correspondences.h"
#include "sift_hull/Octomap.h"
#include "sift_hull/hull/hull_pipeline.h"
#include "sift_hull/io/calibration.h"
#include "sift_hull/synthetic/scene.h"
#include "sift_hull/synthetic/shape.h"

namespace sift_hull {
namespace bad_inputs {

using test::kDeadline_s;
using test::occupiedVolume;
using test::waitFor;

inline constexpr long kMaxRssGrowthKiB = 200 * 1024;  // 200 MiB
inline constexpr int kFlood = 200;
/// 4 * (2^30 + 250) = 2^32 + 1000: a height x step that wraps to the 1000 bytes sent in 32 bits
/// (../shared/repro/matcher_wrap_crash.py).
inline constexpr uint32_t kWrapStep = (1u << 30) + 250;

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

inline Rosout& rosout() {
  static Rosout instance;
  return instance;
}

inline std::string joined(const std::vector<std::string>& needles) {
  std::string text;
  for (const std::string& needle : needles) text += (text.empty() ? "\"" : " + \"") + needle + "\"";
  return text;
}

/// Waits for an error of `node` holding every one of `needles`, logged after `since`.
inline ::testing::AssertionResult loggedError(const std::string& node,
                                              const std::vector<std::string>& needles,
                                              size_t since) {
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
inline int nodePid(const std::string& node) {
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

/// A memory field of /proc/PID/status ("VmRSS:", "VmHWM:") in KiB, -1 when it cannot be read.
inline long statusKiB(int pid, const std::string& field) {
  std::ifstream status("/proc/" + std::to_string(pid) + "/status");
  std::string line;
  while (std::getline(status, line)) {
    if (line.rfind(field, 0) == 0) return std::stol(line.substr(field.size()));
  }
  return -1;
}

/// VmRSS (resident memory now) of a process in KiB, -1 when it cannot be read.
inline long rssKiB(int pid) { return statusKiB(pid, "VmRSS:"); }

/// VmHWM (peak resident memory) of a process in KiB, -1 when it cannot be read.
inline long peakRssKiB(int pid) { return statusKiB(pid, "VmHWM:"); }

/// Whether the process is there and not a zombie.
inline bool processRunning(int pid) {
  std::ifstream status("/proc/" + std::to_string(pid) + "/status");
  std::string line;
  while (std::getline(status, line)) {
    if (line.rfind("State:", 0) == 0) return line.find('Z') == std::string::npos;
  }
  return false;
}

/// Stamps that never repeat, so that no two test messages meet in a synchroniser by accident.
inline ros::Time freshStamp() {
  static ros::Time last;
  ros::Time now = ros::Time::now();
  if (now <= last) now = last + ros::Duration(0, 1000);
  last = now;
  return now;
}

inline sensor_msgs::Image imageMessage(const cv::Mat& image, const ros::Time& stamp,
                                       const std::string& frame) {
  std_msgs::Header header;
  header.stamp = stamp;
  header.frame_id = frame;
  return ros_conversions::imageMessage(image, header);
}

/// mono8 with the wrap-style step: 4 rows 2^30 + 250 bytes apart in 1000 bytes.
inline sensor_msgs::Image wrapStepImage(const ros::Time& stamp, const std::string& frame) {
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

}  // namespace bad_inputs
}  // namespace sift_hull
