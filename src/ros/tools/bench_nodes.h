#pragma once
// What the parts of bench-nodes share: waiting on the harness, listening to a node's diagnostics
// and outputs, and the results of the matcher and hull runs (bench_nodes_matcher.cpp,
// bench_nodes_hull.cpp, cmd_bench_nodes.cpp).

#include <diagnostic_msgs/DiagnosticArray.h>
#include <ros/ros.h>
#include <sensor_msgs/CameraInfo.h>
#include <sensor_msgs/Image.h>
#include <std_srvs/Empty.h>
#include <tf2_ros/transform_broadcaster.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <iomanip>
#include <iostream>
#include <map>
#include <mutex>
#include <opencv2/core.hpp>
#include <sstream>
#include <thread>

#include "args.h"
#include "bench_measure.h"
#include "bench_report.h"
#include "commands.h"
#include "hull_options.h"
#include "lib/conversions.h"
#include "lib/wall_wait.h"
#include "nodes/matcher_node.h"
#include "pair_data.h"
#include "ros_harness.h"
#include "sift_hull/Correspondences.h"
#include "sift_hull/Octomap.h"
#include "sift_hull/hull/hull_pipeline.h"
#include "sift_hull/synthetic/scene.h"

namespace sift_hull {
namespace cli {
namespace bench_nodes {

inline constexpr double kDeadline_s = 30.0;

/// Waits (the AsyncSpinner spins) until `done` holds or the deadline passes.
inline bool waitUntil(const std::function<bool()>& done, double seconds = kDeadline_s) {
  return waitOnWallClock(done, seconds, 0.005);
}

/// The latest values of one node's diagnostics task, e.g. "pairs dropped".
class DiagnosticsListener {
 public:
  DiagnosticsListener(ros::NodeHandle& nh, std::string task)
      : task_(std::move(task)),
        sub_(nh.subscribe("/diagnostics", 10, &DiagnosticsListener::onArray, this)) {}

  double value(const std::string& key) const {
    std::lock_guard<std::mutex> lock(mutex_);
    const auto found = values_.find(key);
    return found == values_.end() ? -1.0 : std::stod(found->second);
  }

 private:
  void onArray(const diagnostic_msgs::DiagnosticArrayConstPtr& array) {
    for (const diagnostic_msgs::DiagnosticStatus& status : array->status) {
      if (status.name.size() < task_.size() ||
          status.name.compare(status.name.size() - task_.size(), task_.size(), task_) != 0) {
        continue;
      }
      std::lock_guard<std::mutex> lock(mutex_);
      for (const diagnostic_msgs::KeyValue& pair : status.values) values_[pair.key] = pair.value;
    }
  }

  std::string task_;
  mutable std::mutex mutex_;
  std::map<std::string, std::string> values_;
  ros::Subscriber sub_;
};

/// When each output stamp arrived (wall time).
template <typename Message>
class ArrivalLog {
 public:
  ArrivalLog(ros::NodeHandle& nh, const std::string& topic)
      : sub_(nh.subscribe(topic, 100, &ArrivalLog::onMessage, this)) {}

  std::optional<ros::WallTime> arrival(const ros::Time& stamp) const {
    std::lock_guard<std::mutex> lock(mutex_);
    const auto found = arrivals_.find(stamp);
    if (found == arrivals_.end()) return std::nullopt;
    return found->second;
  }
  size_t count() const {
    std::lock_guard<std::mutex> lock(mutex_);
    return arrivals_.size();
  }
  bool connected() const { return sub_.getNumPublishers() > 0; }
  /// The newest message, or null.
  boost::shared_ptr<const Message> last() const {
    std::lock_guard<std::mutex> lock(mutex_);
    return last_;
  }

 private:
  void onMessage(const boost::shared_ptr<const Message>& message) {
    std::lock_guard<std::mutex> lock(mutex_);
    arrivals_.emplace(message->header.stamp, ros::WallTime::now());
    last_ = message;
  }

  mutable std::mutex mutex_;
  std::map<ros::Time, ros::WallTime> arrivals_;
  boost::shared_ptr<const Message> last_;
  ros::Subscriber sub_;
};

inline std::vector<std::string> nodeArguments(const std::string& name,
                                              std::vector<std::string> parameters) {
  parameters.insert(parameters.begin(), {"__name:=" + name, "_diagnostic_period:=0.2"});
  return parameters;
}

struct MatcherRun {
  int workers = 0;
  double input_hz = 0.0;
  int width_px = 0, height_px = 0;
  int published = 0, answered = 0;
  double answered_per_s = 0.0, latency_ms = 0.0, dropped = 0.0;
  double described = 0.0, reused = 0.0;  ///< the node's feature cache: images described, reused
  double rss_first_mib = 0.0, rss_last_mib = 0.0, rss_max_mib = 0.0;
  /// Resident set after the warm-up, and 10 s after the stream was settled (freed memory back).
  double rss_idle_mib = 0.0, rss_10s_after_mib = 0.0;
};

struct StereoStream {
  std::vector<sensor_msgs::Image> frames;  ///< the scene's views; pair k is frames k and k + 1
  std::vector<cv::Mat> images;             ///< the same views as images
};

/// What one SIFT of a stream frame costs in this process (the node's default SiftConfig): the
/// floor under the node's time per pair, which describes at least one new image per pair.
struct SiftCost {
  double one_thread_ms = 0.0, all_threads_ms = 0.0;
  double keypoints = 0.0;  ///< median per frame
};

SiftCost measureSift(const StereoStream& stream);

/// The synthetic scene's 16 views at width x height pixels, as image messages.
StereoStream stereoStream(int width_px = 640, int height_px = 480);

/// matcher_node with `workers` workers, fed pairs at `input_hz` for `seconds`; then 10 s idle.
MatcherRun runMatcher(RosHarness& harness, const StereoStream& stream, int workers, double input_hz,
                      double seconds);

struct HullRun {
  std::string name;
  int views = 0, depth = 0, incremental_views = 0;
  double carve_ms = 0.0, publish_ms = 0.0, latency_ms = 0.0;  ///< medians, incremental views
  /// The node's finest cell edge (its last octomap's) and `sift_hull hull`'s on the same views.
  double resolution_m = 0.0, cli_resolution_m = 0.0;
  // At 10 Hz: the views once each after a ~reset, latency median over those that refined a hull.
  int rate_published = 0;
  double rate_dropped = 0.0, rate_latency_ms = 0.0;
  // Overload: the views again and again, faster than they are carved.
  double overload_hz = 0.0;
  int overload_published = 0;
  double overload_processed = 0.0, overload_redundant = 0.0, overload_dropped = 0.0;
  double rss_first_mib = 0.0, rss_last_mib = 0.0;
};

/// hull_node at `depth` fed the views one at a time, then once each at 10 Hz after a ~reset,
/// then again and again at 100 Hz.
HullRun runHull(RosHarness& harness, const std::string& name, const HullInput& input, int depth);

/// runHull on the synthetic scene, and on dino when `data_root` holds it.
std::vector<HullRun> benchHulls(RosHarness& harness, const std::string& data_root);

}  // namespace bench_nodes
}  // namespace cli
}  // namespace sift_hull
