// bench-nodes: the matcher and hull nodes as users run them, in processes of their own against a
// ROS master of their own, fed over topics by this program: the matcher on a 640x480 stereo
// stream at several rates (1 worker, the baseline, and 2), the hull node one view at a time at
// depth 8, and both under a stream faster than they can follow (drops counted, memory sampled).

#include <diagnostic_msgs/DiagnosticArray.h>
#include <ros/ros.h>
#include <sensor_msgs/CameraInfo.h>
#include <sensor_msgs/Image.h>
#include <tf2_ros/transform_broadcaster.h>

#include <algorithm>
#include <filesystem>
#include <iomanip>
#include <iostream>
#include <map>
#include <mutex>
#include <sstream>
#include <thread>

#include "lib/conversions.h"
#include "nodes/matcher_node.h"
#include "lib/wall_wait.h"
#include "args.h"
#include "bench_timing.h"
#include "commands.h"
#include "hull_options.h"
#include "pair_data.h"
#include "ros_harness.h"
#include "sift_hull/Correspondences.h"
#include "sift_hull/Octomap.h"
#include "sift_hull/hull/hull_pipeline.h"
#include "sift_hull/synthetic/scene.h"

namespace sift_hull {
namespace cli {
namespace {

constexpr double kDeadline_s = 30.0;

/// Waits (the AsyncSpinner spins) until `done` holds or the deadline passes.
bool waitUntil(const std::function<bool()>& done, double seconds = kDeadline_s) {
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

 private:
  void onMessage(const boost::shared_ptr<const Message>& message) {
    std::lock_guard<std::mutex> lock(mutex_);
    arrivals_.emplace(message->header.stamp, ros::WallTime::now());
  }

  mutable std::mutex mutex_;
  std::map<ros::Time, ros::WallTime> arrivals_;
  ros::Subscriber sub_;
};

std::vector<std::string> nodeArguments(const std::string& name,
                                       std::vector<std::string> parameters) {
  parameters.insert(parameters.begin(), {"__name:=" + name, "_diagnostic_period:=0.2"});
  return parameters;
}

// ---- matcher ---------------------------------------------------------------------------------

struct MatcherRun {
  int workers = 0;
  double input_hz = 0.0;
  int published = 0, answered = 0;
  double answered_per_s = 0.0, latency_ms = 0.0, dropped = 0.0;
  double rss_first_mib = 0.0, rss_last_mib = 0.0, rss_max_mib = 0.0;
};

struct StereoStream {
  std::vector<sensor_msgs::Image> frames;  ///< the scene's views; pair k is frames k and k + 1
};

StereoStream stereoStream() {
  SceneConfig config;  // 16 views, 640x480
  StereoStream stream;
  for (const RenderedView& view : renderScene(config)) {
    stream.frames.push_back(ros_conversions::imageMessage(view.image, std_msgs::Header()));
  }
  return stream;
}

class MatcherFeed {
 public:
  MatcherFeed(ros::NodeHandle& nh, const StereoStream& stream)
      : stream_(stream),
        left_(nh.advertise<sensor_msgs::Image>("left/image", 2)),
        right_(nh.advertise<sensor_msgs::Image>("right/image", 2)) {}

  bool connected() const { return left_.getNumSubscribers() > 0 && right_.getNumSubscribers() > 0; }
  ros::Time publish(int k, const std::string& frame_suffix = "") {
    const size_t n = stream_.frames.size();
    sensor_msgs::Image left = stream_.frames[k % n], right = stream_.frames[(k + 1) % n];
    left.header.stamp = right.header.stamp = ros::Time::now();
    left.header.frame_id = "left" + frame_suffix;
    right.header.frame_id = "right" + frame_suffix;
    left_.publish(left);
    right_.publish(right);
    return left.header.stamp;
  }

 private:
  const StereoStream& stream_;
  ros::Publisher left_, right_;
};

using SendTimes = std::map<ros::Time, ros::WallTime>;

/// Sends pairs at `run->input_hz` for `seconds`, sampling the node's memory; when each was sent.
SendTimes streamPairs(MatcherFeed& feed, pid_t pid, double seconds, MatcherRun* run) {
  SendTimes sent;
  const ros::WallTime start = ros::WallTime::now();
  for (int k = 0; (ros::WallTime::now() - start).toSec() < seconds; ++k) {
    const ros::WallTime due = start + ros::WallDuration(k / run->input_hz);
    if (ros::WallTime::now() < due) (due - ros::WallTime::now()).sleep();
    sent[feed.publish(k)] = ros::WallTime::now();
    const double rss = residentMiB(pid);
    if (run->rss_first_mib == 0.0 && (ros::WallTime::now() - start).toSec() > 1.0) {
      run->rss_first_mib = rss;
    }
    run->rss_max_mib = std::max(run->rss_max_mib, rss);
  }
  return sent;
}

/// Answered rate (from the first pair sent to the last answer) and median latency.
void summariseAnswers(const SendTimes& sent, const ArrivalLog<sift_hull::Correspondences>& answers,
                      MatcherRun* run) {
  std::vector<double> latencies;
  const ros::WallTime start = sent.begin()->second;
  ros::WallTime last_answer = start;
  for (const auto& [stamp, when] : sent) {
    const std::optional<ros::WallTime> arrival = answers.arrival(stamp);
    if (!arrival) continue;
    latencies.push_back((*arrival - when).toSec() * 1e3);
    last_answer = std::max(last_answer, *arrival);
  }
  run->answered = static_cast<int>(latencies.size());
  run->answered_per_s = run->answered / std::max((last_answer - start).toSec(), 1e-9);
  run->latency_ms = median(latencies);
}

MatcherRun runMatcher(RosHarness& harness, const StereoStream& stream, int workers, double input_hz,
                      double seconds) {
  const pid_t pid = harness.startNode(
      "matcher_node", nodeArguments("matcher", {"_workers:=" + std::to_string(workers)}));
  ros::NodeHandle nh;
  MatcherFeed feed(nh, stream);
  ArrivalLog<sift_hull::Correspondences> answers(nh, "correspondences");
  DiagnosticsListener diagnostics(nh, "matcher");
  if (!waitUntil([&] { return feed.connected() && answers.connected(); })) {
    throw std::runtime_error("bench-nodes: matcher_node did not connect");
  }
  for (int k = 0; k < 2; ++k) {  // warm-up, answered one by one
    const ros::Time stamp = feed.publish(k);
    waitUntil([&] { return answers.arrival(stamp).has_value(); });
  }
  MatcherRun run{workers, input_hz};
  const SendTimes sent = streamPairs(feed, pid, seconds, &run);
  run.published = static_cast<int>(sent.size());
  waitUntil(
      [&] {
        const double settled =
            diagnostics.value("pairs processed") + diagnostics.value("pairs dropped");
        return settled >= run.published + 2;  // and the two of the warm-up
      },
      10.0);
  run.rss_last_mib = residentMiB(pid);
  run.dropped = diagnostics.value("pairs dropped");
  summariseAnswers(sent, answers, &run);
  harness.stopNode(pid);
  return run;
}

// ---- hull ------------------------------------------------------------------------------------

struct HullRun {
  std::string name;
  int views = 0, depth = 0, incremental_views = 0;
  double carve_ms = 0.0, publish_ms = 0.0, latency_ms = 0.0;  ///< medians, incremental views
  // Overload: the views again and again, faster than they are carved.
  double overload_hz = 0.0;
  int overload_published = 0;
  double overload_processed = 0.0, overload_redundant = 0.0, overload_dropped = 0.0;
  double rss_first_mib = 0.0, rss_last_mib = 0.0;
};

class HullFeed {
 public:
  HullFeed(ros::NodeHandle& nh, const HullInput& input)
      : input_(input),
        silhouette_(nh.advertise<sensor_msgs::Image>("silhouette", 20)),
        info_(nh.advertise<sensor_msgs::CameraInfo>("camera_info", 20)) {
    std_msgs::Header header;
    for (const cv::Mat& mask : input.masks) {
      masks_.push_back(ros_conversions::imageMessage(mask, header));
    }
  }

  bool connected() const {
    return silhouette_.getNumSubscribers() > 0 && info_.getNumSubscribers() > 0;
  }
  ros::Time publish(size_t index) {
    const size_t i = index % input_.masks.size();
    const ros::Time stamp = ros::Time::now();
    tf_.sendTransform(
        ros_conversions::cameraPoseMessage(input_.cameras[i], "world", "camera", stamp));
    sensor_msgs::Image mask = masks_[i];
    mask.header.stamp = stamp;
    mask.header.frame_id = "camera";
    info_.publish(
        ros_conversions::cameraInfoMessage(input_.cameras[i], input_.masks[i].size(), mask.header));
    silhouette_.publish(mask);
    return stamp;
  }

 private:
  const HullInput& input_;
  std::vector<sensor_msgs::Image> masks_;
  ros::Publisher silhouette_, info_;
  tf2_ros::TransformBroadcaster tf_;
};

void measureViews(HullFeed& feed, const ArrivalLog<sift_hull::Octomap>& octomaps,
                  const DiagnosticsListener& diagnostics, HullRun* run) {
  std::vector<double> carve, publish, latency;
  bool had_hull = false;
  for (int i = 0; i < run->views; ++i) {
    const ros::WallTime sent = ros::WallTime::now();
    const ros::Time stamp = feed.publish(i);
    if (!waitUntil([&] { return diagnostics.value("views processed") >= i + 1; })) {
      throw std::runtime_error("bench-nodes: hull_node did not process view " + std::to_string(i));
    }
    // A view that changed the hull is followed by its octomap; give it a moment to arrive.
    waitUntil([&] { return octomaps.arrival(stamp).has_value(); }, 0.5);
    const std::optional<ros::WallTime> arrival = octomaps.arrival(stamp);
    if (had_hull && arrival) {  // refined an existing hull: the incremental case
      carve.push_back(diagnostics.value("last view carve ms"));
      publish.push_back(diagnostics.value("last view publish ms"));
      latency.push_back((*arrival - sent).toSec() * 1e3);
    }
    had_hull = had_hull || arrival.has_value();
  }
  run->incremental_views = static_cast<int>(carve.size());
  run->carve_ms = median(carve);
  run->publish_ms = median(publish);
  run->latency_ms = median(latency);
}

void overload(HullFeed& feed, const DiagnosticsListener& diagnostics, pid_t pid, HullRun* run) {
  run->overload_hz = 100.0;
  const double processed_before = diagnostics.value("views processed");
  const double redundant_before = diagnostics.value("views redundant");
  const ros::WallTime start = ros::WallTime::now();
  for (int k = 0; (ros::WallTime::now() - start).toSec() < 5.0; ++k) {
    const ros::WallTime due = start + ros::WallDuration(k / run->overload_hz);
    if (ros::WallTime::now() < due) (due - ros::WallTime::now()).sleep();
    feed.publish(k);
    ++run->overload_published;
    if (k == static_cast<int>(run->overload_hz)) run->rss_first_mib = residentMiB(pid);
  }
  const double received = processed_before + run->overload_published;
  waitUntil(
      [&] {
        return diagnostics.value("views processed") + diagnostics.value("views dropped") >=
                   received &&
               diagnostics.value("views waiting") == 0.0;
      },
      20.0);
  run->rss_last_mib = residentMiB(pid);
  run->overload_processed = diagnostics.value("views processed") - processed_before;
  run->overload_redundant = diagnostics.value("views redundant") - redundant_before;
  run->overload_dropped = diagnostics.value("views dropped");
}

HullRun runHull(RosHarness& harness, const std::string& name, const HullInput& input, int depth) {
  const pid_t pid = harness.startNode(
      "hull_node",
      nodeArguments("hull", {"_depth:=" + std::to_string(depth), "_world_frame:=world"}));
  ros::NodeHandle nh;
  HullFeed feed(nh, input);
  ArrivalLog<sift_hull::Octomap> octomaps(nh, "octomap_binary");
  DiagnosticsListener diagnostics(nh, "hull");
  if (!waitUntil([&] { return feed.connected() && octomaps.connected(); })) {
    throw std::runtime_error("bench-nodes: hull_node did not connect");
  }
  ros::WallDuration(0.5).sleep();  // tf listener of the node
  HullRun run{name, static_cast<int>(input.masks.size()), depth};
  measureViews(feed, octomaps, diagnostics, &run);
  overload(feed, diagnostics, pid, &run);
  harness.stopNode(pid);
  return run;
}

// ---- report ----------------------------------------------------------------------------------

nlohmann::json matcherJson(const MatcherRun& r) {
  return {{"workers", r.workers},
          {"input_hz", r.input_hz},
          {"published", r.published},
          {"answered", r.answered},
          {"answered_per_s", r.answered_per_s},
          {"latency_median_ms", r.latency_ms},
          {"dropped", r.dropped},
          {"rss_first_mib", r.rss_first_mib},
          {"rss_last_mib", r.rss_last_mib},
          {"rss_max_mib", r.rss_max_mib}};
}

nlohmann::json hullJson(const HullRun& r) {
  return {{"name", r.name},
          {"views", r.views},
          {"depth", r.depth},
          {"incremental_views", r.incremental_views},
          {"carve_median_ms", r.carve_ms},
          {"publish_median_ms", r.publish_ms},
          {"latency_median_ms", r.latency_ms},
          {"overload",
           {{"input_hz", r.overload_hz},
            {"published", r.overload_published},
            {"processed", r.overload_processed},
            {"redundant", r.overload_redundant},
            {"dropped", r.overload_dropped},
            {"rss_first_mib", r.rss_first_mib},
            {"rss_last_mib", r.rss_last_mib}}}};
}

nlohmann::json targetsJson(const std::vector<MatcherRun>& matcher,
                           const std::vector<HullRun>& hulls) {
  double best_rate = 0.0;
  for (const MatcherRun& r : matcher) {
    if (r.workers == MatcherNodeConfig().workers) best_rate = std::max(best_rate, r.answered_per_s);
  }
  double worst_carve = 0.0;
  for (const HullRun& r : hulls) worst_carve = std::max(worst_carve, r.carve_ms);
  return {
      {"matcher_pairs_per_s>=10", {{"measured", best_rate}, {"met", best_rate >= 10.0}}},
      {"hull_view_depth8_ms<=50", {{"measured_ms", worst_carve}, {"met", worst_carve <= 50.0}}}};
}

std::string markdownReport(const std::vector<MatcherRun>& matcher,
                           const std::vector<HullRun>& hulls, const nlohmann::json& targets) {
  std::ostringstream out;
  out << "Written by `sift_hull bench-nodes --write docs/BENCHMARKS.md` on " << todayUtc() << ", "
      << std::thread::hardware_concurrency() << " hardware threads. The nodes run as processes "
      << "of their own against a ROS master of their own; this program publishes their input and "
      << "subscribes their output over TCP, as `rosbag play` and rviz would.\n\n"
      << "Matcher node, 640x480 synthetic stereo pairs (the scene's views k and k+1), filter gsc, "
      << "one pair at a time waiting (`~max_waiting_pairs` 2). Answered per second counts from "
      << "the first pair sent to the last answer; latency is from sending a pair to receiving its "
      << "correspondences (median); dropped is the node's own count (/diagnostics); memory is "
      << "the node's resident set after 1 s / at the end / at most.\n\n"
      << "| workers | input Hz | sent | answered | answered / s | latency ms | dropped | "
         "memory MiB |\n|---|---|---|---|---|---|---|---|\n";
  for (const MatcherRun& r : matcher) {
    out << "| " << r.workers << " | " << fixed(r.input_hz, 0) << " | " << r.published << " | "
        << r.answered << " | " << fixed(r.answered_per_s, 1) << " | " << fixed(r.latency_ms, 0)
        << " | " << fixed(r.dropped, 0) << " | " << fixed(r.rss_first_mib, 0) << " / "
        << fixed(r.rss_last_mib, 0) << " / " << fixed(r.rss_max_mib, 0) << " |\n";
  }
  out << "\nHull node, one view at a time (the next sent once /diagnostics counts the view "
      << "processed). Medians over the views that refine an existing hull: carving (`HullStream` "
      << "add), publishing (OctoMap conversion, octomap_binary and occupied_cells), and the "
      << "latency from sending a view to receiving its octomap. Then the same views again and "
      << "again at 100 Hz for 5 s (`~queue_size` 10): processed counts the views the worker took, "
      << "redundant those of them left out because a view was already taken from there "
      << "(`~min_view_distance_m`, `~min_view_angle_deg`), dropped those the full queue lost; "
      << "memory is the node's resident set after 1 s / at the end.\n\n"
      << "| data | views | depth | carve ms | publish ms | latency ms | 100 Hz: sent / processed / "
         "redundant / dropped | memory MiB |\n|---|---|---|---|---|---|---|---|\n";
  for (const HullRun& r : hulls) {
    out << "| " << r.name << " | " << r.views << " (" << r.incremental_views << " refining) | "
        << r.depth << " | " << fixed(r.carve_ms, 1) << " | " << fixed(r.publish_ms, 1) << " | "
        << fixed(r.latency_ms, 1) << " | " << r.overload_published << " / "
        << fixed(r.overload_processed, 0) << " / " << fixed(r.overload_redundant, 0) << " / "
        << fixed(r.overload_dropped, 0) << " | " << fixed(r.rss_first_mib, 0) << " / "
        << fixed(r.rss_last_mib, 0) << " |\n";
  }
  out << '\n' << targetsMarkdown(targets);
  return out.str();
}

std::vector<HullRun> benchHulls(RosHarness& harness, const std::string& data_root) {
  std::vector<HullRun> runs;
  runs.push_back(runHull(harness, "synthetic", hullInputOf(renderScene(SceneConfig())), 8));
  const HullDataset& dino = hullDatasets().front();
  const std::string directory = data_root + "/" + dino.directory;
  if (data_root.empty() || !std::filesystem::exists(directory)) {
    std::cerr << "bench-nodes: skipping dino: no " << directory << '\n';
    return runs;
  }
  runs.push_back(runHull(harness, dino.name, loadHullDataset(data_root, dino), 8));
  return runs;
}

}  // namespace

int runBenchNodes(const std::vector<std::string>& args) {
  ArgParser parser("bench-nodes",
                   "Measures matcher_node and hull_node as separate processes: the matcher on a\n"
                   "640x480 stereo stream (1 and 2 workers), the hull node one view at a time at\n"
                   "depth 8, and both under a stream faster than they follow.");
  parser.addOption("data", "DIR", "data root (default: $SIFT_HULL_DATA or ../shared/data)");
  parser.addOption("seconds", "S", "length of each matcher stream", "10");
  parser.addOption("write", "MD", "replace the bench-nodes section of this Markdown file");
  parser.addFlag("json", "print the result as one JSON object");
  if (!parser.parse(args)) return 0;
  const double seconds = parser.getDouble("seconds");
  if (!(seconds > 0.0)) throw UsageError("--seconds must be positive");

  RosHarness harness;
  std::cerr << "bench-nodes: the nodes' output goes to " << harness.logPath() << '\n';
  int argc = 0;
  ros::init(argc, nullptr, "bench_nodes", ros::init_options::NoSigintHandler);
  ros::AsyncSpinner spinner(2);
  spinner.start();
  const StereoStream stream = stereoStream();
  std::vector<MatcherRun> matcher;
  for (int workers : {1, 2}) {
    for (double hz : {10.0, 30.0})
      matcher.push_back(runMatcher(harness, stream, workers, hz, seconds));
  }
  const std::string root = parser.has("data") ? parser.get("data") : defaultDataRoot();
  const std::vector<HullRun> hulls = benchHulls(harness, root);
  spinner.stop();
  ros::shutdown();

  nlohmann::json json = {{"matcher", nlohmann::json::array()},
                         {"hull", nlohmann::json::array()},
                         {"targets", targetsJson(matcher, hulls)}};
  for (const MatcherRun& r : matcher) json["matcher"].push_back(matcherJson(r));
  for (const HullRun& r : hulls) json["hull"].push_back(hullJson(r));
  const std::string report = markdownReport(matcher, hulls, json["targets"]);
  if (parser.has("write")) replaceMarkedSection(parser.get("write"), "bench-nodes", report);
  printResult(parser.flag("json"), json, report);
  return 0;
}

}  // namespace cli
}  // namespace sift_hull
