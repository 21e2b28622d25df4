// bench-nodes: the matcher and hull nodes as users run them, in processes of their own against a
// ROS master of their own, fed over topics by this program: the matcher on a 640x480 stereo
// stream at several rates (1 worker, the baseline, and 2) and flooded with 1280x960 pairs, the
// hull node one view at a time at depth 8, and both under a stream faster than they can follow
// (drops counted, memory sampled, and 10 s after the matcher's streams).

#include "bench_nodes.h"

namespace sift_hull {
namespace cli {
namespace {

using namespace bench_nodes;

/// The matcher's stream (the flood's frames are twice as wide and high).
constexpr int kStreamWidth_px = 640, kStreamHeight_px = 480;

// ---- report ----------------------------------------------------------------------------------

nlohmann::json matcherJson(const MatcherRun& r) {
  return {{"workers", r.workers},
          {"input_hz", r.input_hz},
          {"width_px", r.width_px},
          {"height_px", r.height_px},
          {"published", r.published},
          {"answered", r.answered},
          {"answered_per_s", r.answered_per_s},
          {"latency_median_ms", r.latency_ms},
          {"dropped", r.dropped},
          {"images_described", r.described},
          {"features_reused", r.reused},
          {"rss_first_mib", r.rss_first_mib},
          {"rss_last_mib", r.rss_last_mib},
          {"rss_max_mib", r.rss_max_mib},
          {"rss_idle_mib", r.rss_idle_mib},
          {"rss_10s_after_mib", r.rss_10s_after_mib}};
}

nlohmann::json hullJson(const HullRun& r) {
  return {{"name", r.name},
          {"views", r.views},
          {"depth", r.depth},
          {"incremental_views", r.incremental_views},
          {"carve_median_ms", r.carve_ms},
          {"publish_median_ms", r.publish_ms},
          {"latency_median_ms", r.latency_ms},
          {"resolution_m", r.resolution_m},
          {"cli_resolution_m", r.cli_resolution_m},
          {"at_10_hz",
           {{"published", r.rate_published},
            {"dropped", r.rate_dropped},
            {"latency_median_ms", r.rate_latency_ms}}},
          {"overload",
           {{"input_hz", r.overload_hz},
            {"published", r.overload_published},
            {"processed", r.overload_processed},
            {"redundant", r.overload_redundant},
            {"dropped", r.overload_dropped},
            {"rss_first_mib", r.rss_first_mib},
            {"rss_last_mib", r.rss_last_mib}}}};
}

/// What the targets of docs/BENCHMARKS.md are judged on: the matcher's best rate with its default
/// workers and the pairs it lost at 10 Hz; the hull node's worst median latency, its largest
/// relative difference of resolution from `sift_hull hull`'s and the views it dropped at 10 Hz.
nlohmann::json measurementsJson(const std::vector<MatcherRun>& matcher,
                                const std::vector<HullRun>& hulls) {
  double best_rate = 0.0, dropped_at_10_hz = 0.0;
  for (const MatcherRun& r : matcher) {
    if (r.workers != MatcherNodeConfig().workers || r.width_px != kStreamWidth_px) continue;
    best_rate = std::max(best_rate, r.answered_per_s);
    if (r.input_hz <= 10.0) dropped_at_10_hz += r.dropped + (r.published - r.answered);
  }
  double worst_latency = 0.0, worst_resolution = 0.0, dropped = 0.0;
  for (const HullRun& r : hulls) {
    worst_latency = std::max(worst_latency, r.latency_ms);
    worst_resolution =
        std::max(worst_resolution, std::abs(r.resolution_m / r.cli_resolution_m - 1.0));
    dropped += r.rate_dropped;
  }
  return {{"matcher_pairs_per_s", best_rate},
          {"matcher_pairs_dropped_at_10_hz", dropped_at_10_hz},
          {"hull_view_to_octomap_depth8_median_ms", worst_latency},
          {"hull_resolution_relative_difference_to_cli", worst_resolution},
          {"hull_views_dropped_at_10_hz", dropped}};
}

nlohmann::json siftJson(const SiftCost& sift) {
  const double cores = std::thread::hardware_concurrency();
  return {{"keypoints_per_frame", sift.keypoints},
          {"one_thread_ms", sift.one_thread_ms},
          {"all_threads_ms", sift.all_threads_ms},
          // Each answered pair needs one new SIFT at least (its other image cached), two at most.
          {"pairs_per_s_at_most", cores * 1e3 / std::max(sift.one_thread_ms, 1e-9)},
          {"pairs_per_s_at_most_without_cache",
           cores * 1e3 / std::max(2.0 * sift.one_thread_ms, 1e-9)}};
}

std::string siftMarkdown(const nlohmann::json& sift) {
  if (sift.is_null()) return "";
  std::ostringstream out;
  out << "SIFT of one of these frames in this process ("
      << fixed(sift["keypoints_per_frame"].get<double>(), 0)
      << " keypoints, the node's SIFT settings): " << fixed(sift["one_thread_ms"].get<double>(), 1)
      << " ms on one thread, " << fixed(sift["all_threads_ms"].get<double>(), 1)
      << " ms on all. A pair needs one new SIFT when its other image is cached, two when not, so "
      << "the cores answer at most " << fixed(sift["pairs_per_s_at_most"].get<double>(), 1)
      << " pairs/s (" << fixed(sift["pairs_per_s_at_most_without_cache"].get<double>(), 1)
      << " without the cache) before matching, filtering and transport.\n\n";
  return out.str();
}

std::string markdownReport(const std::vector<MatcherRun>& matcher,
                           const std::vector<HullRun>& hulls, const nlohmann::json& measurements,
                           const nlohmann::json& sift) {
  std::ostringstream out;
  out << "Written by `sift_hull_ros bench-nodes --write docs/BENCHMARKS.md` on " << todayUtc()
      << ", CPU " << cpuModel() << " (/proc/cpuinfo), " << std::thread::hardware_concurrency()
      << " hardware threads. The nodes run as processes "
      << "of their own against a ROS master of their own; this program publishes their input and "
      << "subscribes their output over TCP, as `rosbag play` and rviz would.\n\n"
      << "Matcher node, synthetic stereo pairs (the scene's views k and k+1), its "
      << "default filter (" << kDefaultFilter << "), "
      << "one pair at a time waiting (`~max_waiting_pairs` 2). Answered per second counts from "
      << "the first pair sent to the last answer; latency is from sending a pair to receiving its "
      << "correspondences (median); dropped is the node's own count (/diagnostics), described / "
      << "reused its feature cache's (images given to SIFT, images whose features were taken "
      << "from the cache, the warm-up included); memory is "
      << "the node's resident set after the warm-up / at most / 10 s after the stream ended. "
      << "The last row is a flood: 1280x960 pairs at 30 Hz.\n\n"
      << siftMarkdown(sift)
      << "| frames | workers | input Hz | sent | answered | answered / s | latency ms | dropped | "
         "described / reused | memory MiB |\n|---|---|---|---|---|---|---|---|---|---|\n";
  for (const MatcherRun& r : matcher) {
    out << "| " << r.width_px << "x" << r.height_px << " | " << r.workers << " | "
        << fixed(r.input_hz, 0) << " | " << r.published << " | " << r.answered << " | "
        << fixed(r.answered_per_s, 1) << " | " << fixed(r.latency_ms, 0) << " | "
        << fixed(r.dropped, 0) << " | " << fixed(r.described, 0) << " / " << fixed(r.reused, 0)
        << " | " << fixed(r.rss_idle_mib, 0) << " / " << fixed(r.rss_max_mib, 0) << " / "
        << fixed(r.rss_10s_after_mib, 0) << " |\n";
  }
  out << "\nHull node, one view at a time (the next sent once /diagnostics counts the view "
      << "processed). Medians over the views that refine an existing hull: carving (`HullStream` "
      << "add), publishing (OctoMap conversion and octomap_binary, the one output this program "
         "subscribes; the centres clouds, octomap_full and the markers are built only when "
         "subscribed), and the "
      << "latency from sending a view to receiving its octomap; the node's finest cell edge "
         "against `sift_hull hull`'s at the same depth on the same views. Then, after a "
         "`~reset`, the views once each at 10 Hz (views dropped, latency). Then the same views "
         "again and "
      << "again at 100 Hz for 5 s (`~queue_size` 10): processed counts the views the worker took, "
      << "redundant those of them left out because a view was already taken from there "
      << "(`~min_view_distance_m`, `~min_view_angle_deg`), dropped those the full queue lost; "
      << "memory is the node's resident set after 1 s / at the end.\n\n"
      << "| data | views | depth | resolution mm (sift_hull hull) | carve ms | publish ms | "
         "latency ms | 10 Hz: dropped, latency ms | 100 Hz: sent / processed / redundant / "
         "dropped | memory MiB |\n|---|---|---|---|---|---|---|---|---|---|\n";
  for (const HullRun& r : hulls) {
    out << "| " << r.name << " | " << r.views << " (" << r.incremental_views << " refining) | "
        << r.depth << " | " << fixed(1e3 * r.resolution_m, 3) << " ("
        << fixed(1e3 * r.cli_resolution_m, 3) << ") | " << fixed(r.carve_ms, 1) << " | "
        << fixed(r.publish_ms, 1) << " | " << fixed(r.latency_ms, 1) << " | "
        << fixed(r.rate_dropped, 0) << ", " << fixed(r.rate_latency_ms, 1) << " | "
        << r.overload_published << " / " << fixed(r.overload_processed, 0) << " / "
        << fixed(r.overload_redundant, 0) << " / " << fixed(r.overload_dropped, 0) << " | "
        << fixed(r.rss_first_mib, 0) << " / " << fixed(r.rss_last_mib, 0) << " |\n";
  }
  out << '\n' << measurementsMarkdown(measurements);
  return out.str();
}

}  // namespace

int runBenchNodes(const std::vector<std::string>& args) {
  ArgParser parser("bench-nodes",
                   "Measures matcher_node and hull_node as separate processes: the matcher on a\n"
                   "640x480 stereo stream (1 and 2 workers) and a 1280x960 flood, the hull node\n"
                   "one view at a time at depth 8, and both under a stream faster than they\n"
                   "follow.");
  parser.addOption("data", "DIR", "data root (default: $SIFT_HULL_DATA or ../shared/data)");
  parser.addOption("seconds", "S", "length of each matcher stream", "10");
  parser.addOption("write", "MD", "replace the bench-nodes section of this Markdown file");
  parser.addFlag("json", "print the result as one JSON object");
  parser.addFlag("hull-only", "measure the hull node alone (not with --write)");
  if (!parser.parse(args)) return 0;
  const double seconds = parser.getDouble("seconds");
  if (!(seconds > 0.0)) throw UsageError("--seconds must be positive");
  if (parser.flag("hull-only") && parser.has("write")) {
    throw UsageError("--hull-only measures part of the report: not with --write");
  }

  RosHarness harness;
  std::cerr << "bench-nodes: the nodes' output goes to " << harness.logPath() << '\n';
  int argc = 0;
  ros::init(argc, nullptr, "bench_nodes", ros::init_options::NoSigintHandler);
  ros::AsyncSpinner spinner(2);
  spinner.start();
  const StereoStream stream = stereoStream(kStreamWidth_px, kStreamHeight_px);
  nlohmann::json sift;
  if (!parser.flag("hull-only")) sift = siftJson(measureSift(stream));
  std::vector<MatcherRun> matcher;
  for (int workers : {1, 2}) {
    for (double hz : {10.0, 30.0}) {
      if (!parser.flag("hull-only")) {
        matcher.push_back(runMatcher(harness, stream, workers, hz, seconds));
      }
    }
  }
  if (!parser.flag("hull-only")) {  // a flood: frames of four times the pixels, as fast
    const StereoStream large = stereoStream(2 * kStreamWidth_px, 2 * kStreamHeight_px);
    matcher.push_back(runMatcher(harness, large, MatcherNodeConfig().workers, 30.0, seconds));
  }
  const std::string root = parser.has("data") ? parser.get("data") : defaultDataRoot();
  const std::vector<HullRun> hulls = benchHulls(harness, root);
  spinner.stop();
  ros::shutdown();

  nlohmann::json json = {{"cpu", cpuModel()},
                         {"hardware_threads", std::thread::hardware_concurrency()},
                         {"sift", sift},
                         {"matcher", nlohmann::json::array()},
                         {"hull", nlohmann::json::array()},
                         {"measurements", measurementsJson(matcher, hulls)}};
  for (const MatcherRun& r : matcher) json["matcher"].push_back(matcherJson(r));
  for (const HullRun& r : hulls) json["hull"].push_back(hullJson(r));
  const std::string report = markdownReport(matcher, hulls, json["measurements"], json["sift"]);
  if (parser.has("write")) replaceMarkedSection(parser.get("write"), "bench-nodes", report);
  printResult(parser.flag("json"), json, report);
  return 0;
}

}  // namespace cli
}  // namespace sift_hull
