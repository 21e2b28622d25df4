// bench-nodes, the hull node: one view at a time, then a stream faster than it carves.

#include "bench_nodes.h"

namespace sift_hull {
namespace cli {
namespace bench_nodes {

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

/// The views once each at 10 Hz from an empty hull (~reset): views dropped, and the latency from
/// sending a view to receiving its octomap for the views that refine the hull.
void atTenHertz(HullFeed& feed, const ArrivalLog<sift_hull::Octomap>& octomaps,
                const DiagnosticsListener& diagnostics, HullRun* run) {
  std_srvs::Empty reset;
  if (!ros::service::call("/hull/reset", reset)) {
    throw std::runtime_error("bench-nodes: hull_node's ~reset failed");
  }
  ros::WallDuration(0.5).sleep();  // the reset's empty map first
  const double dropped_before = diagnostics.value("views dropped");
  const double processed_before = diagnostics.value("views processed");
  std::vector<std::pair<ros::WallTime, ros::Time>> sent;
  const ros::WallTime start = ros::WallTime::now();
  for (int i = 0; i < run->views; ++i) {
    const ros::WallTime due = start + ros::WallDuration(i / 10.0);
    sleepUntilWall(due);
    sent.emplace_back(ros::WallTime::now(), feed.publish(i));
  }
  run->rate_published = run->views;
  waitUntil(
      [&] {
        return diagnostics.value("views processed") + diagnostics.value("views dropped") >=
               processed_before + dropped_before + run->views;
      },
      30.0);
  waitUntil([&] { return octomaps.arrival(sent.back().second).has_value(); }, 2.0);
  run->rate_dropped = diagnostics.value("views dropped") - dropped_before;
  std::vector<double> latency;
  bool had_hull = false;
  for (const auto& [wall, stamp] : sent) {
    const std::optional<ros::WallTime> arrival = octomaps.arrival(stamp);
    if (had_hull && arrival) latency.push_back((*arrival - wall).toSec() * 1e3);
    had_hull = had_hull || arrival.has_value();
  }
  run->rate_latency_ms = median(latency);
}

void overload(HullFeed& feed, const DiagnosticsListener& diagnostics, pid_t pid, HullRun* run) {
  run->overload_hz = 100.0;
  const double processed_before = diagnostics.value("views processed");
  const double redundant_before = diagnostics.value("views redundant");
  const ros::WallTime start = ros::WallTime::now();
  for (int k = 0; (ros::WallTime::now() - start).toSec() < 5.0; ++k) {
    const ros::WallTime due = start + ros::WallDuration(k / run->overload_hz);
    sleepUntilWall(due);
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
      nodeArguments("hull", {"_max_depth:=" + std::to_string(depth), "_world_frame:=world"}));
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
  run.resolution_m = octomaps.last() ? octomaps.last()->resolution : 0.0;
  HullConfig config;
  config.max_depth = depth;
  run.cli_resolution_m = buildHull(input, config).hull.cube().resolution_m;
  atTenHertz(feed, octomaps, diagnostics, &run);
  overload(feed, diagnostics, pid, &run);
  harness.stopNode(pid);
  return run;
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

}  // namespace bench_nodes
}  // namespace cli
}  // namespace sift_hull
