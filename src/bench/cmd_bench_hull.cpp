// bench-hull: the visual hull on dino and temple at depths 7, 8 and 9 against dense voxel carving
// at the same resolution, and a synthetic case of many high-resolution views
// (bench_hull_synthetic.h), in one run; medians of repeated runs.

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <filesystem>
#include <iomanip>
#include <iostream>
#include <map>
#include <sstream>
#include <thread>

#include "args.h"
#include "bench_commands.h"
#include "bench_hull_end_to_end.h"
#include "bench_hull_synthetic.h"
#include "bench_measure.h"
#include "bench_report.h"
#include "bench_scene.h"
#include "commands.h"
#include "hull_options.h"
#include "pair_data.h"
#include "sift_hull/eval/hull_evaluation.h"
#include "sift_hull/hull/hull_config.h"
#include "sift_hull/hull/hull_pipeline.h"
#include "sift_hull/hull/octree.h"

namespace sift_hull {
namespace cli {
namespace {

const std::vector<int> kDepths = {7, 8, 9};

/// One data set at one depth: the hull's stage times (medians), its quality, and dense carving.
struct DepthRun {
  int depth = 0;
  HullTimings time;
  size_t surface_leaves = 0, mesh_faces = 0;
  bool watertight = false;
  ReprojectionIoU iou;
  double dense_ms = 0.0, volume_iou = 0.0;
};

HullTimings medianTimings(const std::vector<HullTimings>& runs) {
  const auto field = [&](double HullTimings::*member) {
    std::vector<double> values;
    for (const HullTimings& run : runs) values.push_back(run.*member);
    return median(values);
  };
  HullTimings time{field(&HullTimings::distance_ms), field(&HullTimings::bbox_ms),
                   field(&HullTimings::octree_ms), field(&HullTimings::mesh_ms),
                   field(&HullTimings::total_ms)};
  time.masks_ms = field(&HullTimings::masks_ms);
  return time;
}

/// Runs the hull at least 3 times (more while under ~2 s) and keeps the last result.
DepthRun timeHull(const HullInput& input, int depth, std::optional<HullResult>* last) {
  HullConfig config;
  config.max_depth = depth;
  std::vector<HullTimings> runs;
  double total_ms = 0.0;
  while (runs.size() < 3 || (total_ms < 2000.0 && runs.size() < 21)) {
    last->reset();
    last->emplace(buildHull(input, config));
    runs.push_back((*last)->time);
    total_ms += runs.back().total_ms;
  }
  DepthRun run;
  run.depth = depth;
  run.time = medianTimings(runs);
  run.surface_leaves = (*last)->hull.stats().surface_leaves;
  run.mesh_faces = (*last)->mesh.faces.size();
  run.watertight = (*last)->mesh_check.watertight;
  run.iou = reprojectionIoU((*last)->mesh, (*last)->hull.views());
  return run;
}

void compareWithDense(const HullResult& result, DepthRun* run) {
  const VisualHull& hull = result.hull;
  const int cells = 1 << hull.cube().depth;
  DenseGrid dense;
  run->dense_ms = medianMs(
      [&] { dense = denseCarving(hull.views(), hull.cube().box(), cells, hull.config().threads); },
      3000.0, 1);
  run->volume_iou = volumeIoU(hull, dense);
}

struct DatasetRuns {
  std::string name;
  size_t views = 0;
  std::vector<DepthRun> depths;
  /// Of a separate `sift_hull hull --max-depth 9` process: through buildHull, and in all.
  double peak_mib_depth9 = 0.0, command_peak_mib_depth9 = 0.0;
  nlohmann::json refinement;     ///< refinementAtDepth8
  nlohmann::json photo_carving;  ///< photoCarvingAtDepth8
};

DatasetRuns benchDataset(const HullInput& input, const std::string& name) {
  DatasetRuns runs{name, input.names.size(), {}, 0.0, 0.0, {}, {}};
  for (int depth : kDepths) {
    std::optional<HullResult> last;
    runs.depths.push_back(timeHull(input, depth, &last));
    compareWithDense(*last, &runs.depths.back());
  }
  return runs;
}

/// The user's program sift_hull, which is installed beside this one (devel/lib/sift_hull, the
/// install space's bin and lib/sift_hull).
std::string userProgram() {
  const std::filesystem::path self = std::filesystem::read_symlink("/proc/self/exe");
  const std::filesystem::path sibling = self.parent_path() / "sift_hull";
  if (!std::filesystem::exists(sibling)) {
    throw std::runtime_error("no sift_hull beside " + self.string() + " to run 'hull' with");
  }
  return sibling.string();
}

/// `sift_hull hull --json` on a data set as a child process (so that nothing else of this
/// benchmark counts), with `extra` options; its JSON.
nlohmann::json hullCommand(const std::string& directory, const HullDataset& dataset,
                           const std::string& extra) {
  std::string command = "'" + userProgram() + "' hull --json " + extra + " --threshold " +
                        std::to_string(dataset.threshold) + " --calib '" + directory + "/" +
                        dataset.calibration + "' --images '" + directory + "'";
  if (!dataset.view_list.empty())
    command += " --views-file '" + directory + "/" + dataset.view_list + "'";
  FILE* pipe = popen(command.c_str(), "r");
  if (pipe == nullptr) throw std::runtime_error("cannot run: " + command);
  std::string output;
  char buffer[4096];
  while (size_t read = fread(buffer, 1, sizeof buffer, pipe)) output.append(buffer, read);
  if (pclose(pipe) != 0) throw std::runtime_error("failed: " + command);
  return nlohmann::json::parse(output);
}

/// Peak memory of the `hull` command at depth 9: {"through_hull": loading, silhouettes and
/// buildHull, "total": also the OctoMap, the IoU and the outputs}.
nlohmann::json hullCommandPeakMiB(const std::string& directory, const HullDataset& dataset) {
  return hullCommand(directory, dataset, "--max-depth 9").at("peak_memory_mib");
}

/// The stages of `hull --max-depth 8 --refine-with-matches` (median of 3 runs, ms), with the
/// hull's own total beside them, the points kept and the reprojection IoU before and after.
nlohmann::json refinementAtDepth8(const std::string& directory, const HullDataset& dataset) {
  std::map<std::string, std::vector<double>> stages;
  nlohmann::json last;
  for (int run = 0; run < 3; ++run) {
    last = hullCommand(directory, dataset, "--max-depth 8 --refine-with-matches");
    for (const auto& [stage, ms] : last.at("refine_time_ms").items()) {
      stages[stage].push_back(ms.get<double>());
    }
    stages["hull"].push_back(last.at("time_ms").at("total").get<double>());
  }
  nlohmann::json json = {{"points_kept", last.at("points").at("kept")},
                         {"carved_volume_m3", last.at("carved_volume_m3")},
                         {"reprojection_iou_before", last.at("reprojection_iou_before")},
                         {"reprojection_iou_after", last.at("reprojection_iou")}};
  for (auto& [stage, values] : stages) json["time_ms"][stage] = median(values);
  return json;
}

/// `hull --max-depth 8 --photo-carve` (median of 3 runs): the whole process's wall time, the
/// hull's own total, photo carving's time and stages, and the reprojection IoU after.
nlohmann::json photoCarvingAtDepth8(const std::string& directory, const HullDataset& dataset) {
  std::map<std::string, std::vector<double>> times;
  nlohmann::json last;
  for (int run = 0; run < 3; ++run) {
    const auto start = std::chrono::steady_clock::now();
    last = hullCommand(directory, dataset, "--max-depth 8 --photo-carve");
    times["process"].push_back(
        std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start)
            .count());
    times["hull"].push_back(last.at("time_ms").at("total").get<double>());
    times["photo_carving"].push_back(last.at("photo_carving").at("time_ms").get<double>());
    for (const auto& [stage, ms] : last.at("photo_carving").at("stage_ms").items()) {
      times[stage].push_back(ms.get<double>());
    }
  }
  nlohmann::json json = {{"carved_volume_m3", last.at("photo_carving").at("carved_volume_m3")},
                         {"reprojection_iou_after", last.at("reprojection_iou")}};
  for (auto& [stage, values] : times) json["time_ms"][stage] = median(values);
  return json;
}

nlohmann::json depthJson(const DepthRun& run) {
  return {{"depth", run.depth},
          {"time_ms",
           {{"distance", run.time.distance_ms},
            {"bbox", run.time.bbox_ms},
            {"octree", run.time.octree_ms},
            {"mesh", run.time.mesh_ms},
            {"total", run.time.total_ms}}},
          {"surface_leaves", run.surface_leaves},
          {"mesh_faces", run.mesh_faces},
          {"watertight", run.watertight},
          {"reprojection_iou", {{"min", run.iou.min}, {"mean", run.iou.mean}}},
          {"dense_ms", run.dense_ms},
          {"volume_iou_vs_dense", run.volume_iou}};
}

std::string markdownTable(const std::vector<DatasetRuns>& all) {
  std::ostringstream out;
  out << "| data (views) | depth | distance | bbox | octree | mesh | total | dense carving | "
         "dense / octree | dense / total | surface leaves | faces | watertight | reproj. IoU "
         "min / mean | volume IoU vs dense |\n"
      << "| --- | --- | --- | --- | --- | --- | --- | --- | --- | --- | --- | --- | --- | --- | "
         "--- |\n";
  for (const DatasetRuns& runs : all) {
    for (const DepthRun& r : runs.depths) {
      out << "| " << runs.name << " (" << runs.views << ") | " << r.depth << " | "
          << fixed(r.time.distance_ms, 1) << " ms | " << fixed(r.time.bbox_ms, 1) << " ms | "
          << fixed(r.time.octree_ms, 1) << " ms | " << fixed(r.time.mesh_ms, 1) << " ms | **"
          << fixed(r.time.total_ms, 1) << " ms** | " << fixed(r.dense_ms, 0) << " ms | "
          << fixed(r.dense_ms / r.time.octree_ms, 1) << "x | "
          << fixed(r.dense_ms / r.time.total_ms, 1) << "x | " << r.surface_leaves << " | "
          << r.mesh_faces << " | " << (r.watertight ? "yes" : "no") << " | " << fixed(r.iou.min, 4)
          << " / " << fixed(r.iou.mean, 4) << " | " << fixed(r.volume_iou, 4) << " |\n";
    }
  }
  return out.str();
}

/// What the targets of docs/BENCHMARKS.md are judged on, each the worse data set's: the total
/// time at depth 8 and 9, dense carving's time over the octree's at depth 8, the peak memory
/// through the hull at depth 9 and the mean reprojection IoU (the lowest of all depths).
/// Table cells "N ms | " of the times `keys` of `times`.
std::string msCells(const nlohmann::json& times, const std::vector<std::string>& keys) {
  std::string cells;
  for (const std::string& key : keys) cells += fixed(times.at(key).get<double>(), 0) + " ms | ";
  return cells;
}

nlohmann::json measurementsJson(const std::vector<DatasetRuns>& all) {
  double worst_8 = 0.0, worst_9 = 0.0, least_speedup = 1e300, least_iou = 1.0, peak_mib = 0.0;
  double photo_s = 0.0;
  for (const DatasetRuns& runs : all) {
    peak_mib = std::max(peak_mib, runs.peak_mib_depth9);
    if (!runs.photo_carving.is_null()) {
      photo_s =
          std::max(photo_s, runs.photo_carving.at("time_ms").at("process").get<double>() / 1e3);
    }
    for (const DepthRun& r : runs.depths) {
      if (r.depth == 8) worst_8 = std::max(worst_8, r.time.total_ms);
      if (r.depth == 8) least_speedup = std::min(least_speedup, r.dense_ms / r.time.octree_ms);
      if (r.depth == 9) worst_9 = std::max(worst_9, r.time.total_ms);
      least_iou = std::min(least_iou, r.iou.mean);
    }
  }
  return {{"depth8_total_ms", worst_8},         {"dense_over_octree_depth8", least_speedup},
          {"depth9_total_ms", worst_9},         {"depth9_peak_mib", peak_mib},
          {"mean_reprojection_iou", least_iou}, {"photo_carving_depth8_process_s", photo_s}};
}

std::string markdownReport(const std::vector<DatasetRuns>& all,
                           const nlohmann::json& measurements) {
  std::ostringstream out;
  out << "Written by `sift_hull_bench bench-hull --write docs/BENCHMARKS.md` on " << todayUtc()
      << ", CPU " << cpuModel() << " (/proc/cpuinfo), " << std::thread::hardware_concurrency()
      << " hardware threads, 2 carving threads. Times are "
      << "medians of at least 3 runs (dense carving: at least 1, more within 3 s).\n\n"
      << markdownTable(all) << "\nPeak resident memory of `sift_hull hull --max-depth 9`, through "
      << "the hull (images, silhouettes, distance maps, octree, mesh) / the whole command (also "
      << "the OctoMap conversion and the IoU rasterisation):";
  for (const DatasetRuns& runs : all) {
    out << ' ' << runs.name << ' ' << fixed(runs.peak_mib_depth9, 0) << " / "
        << fixed(runs.command_peak_mib_depth9, 0) << " MiB;";
  }
  out << "\n\n`sift_hull hull --max-depth 8 --refine-with-matches` (free-space carving from the "
         "filtered matches of neighbouring views; docs/CLI.md), median of 3 runs:\n\n"
      << "| data | hull | matching | points | free voxels | carving | mesh | points kept | "
         "reproj. IoU min before / after |\n| --- | --- | --- | --- | --- | --- | --- | --- | "
         "--- |\n";
  for (const DatasetRuns& runs : all) {
    const nlohmann::json& r = runs.refinement;
    const nlohmann::json& t = r.at("time_ms");
    out << "| " << runs.name << " | "
        << msCells(t, {"hull", "matching", "points", "free_voxels", "carving", "mesh"})
        << r.at("points_kept") << " | "
        << fixed(r.at("reprojection_iou_before").at("min").get<double>(), 4) << " / "
        << fixed(r.at("reprojection_iou_after").at("min").get<double>(), 4) << " |\n";
  }
  out << "\n`sift_hull hull --max-depth 8 --photo-carve` (the hull carved by the views' depth "
         "maps; docs/CLI.md), median of 3 runs: the whole process as a user waits for it, the "
         "hull, photo carving and its stages:\n\n"
      << "| data | process | hull | photo carving | depth maps | consistency | voting | "
         "silhouettes | carved cm^3 | reproj. IoU min |\n| --- | --- | --- | --- | --- | --- | "
         "--- | --- | --- | --- |\n";
  for (const DatasetRuns& runs : all) {
    const nlohmann::json& r = runs.photo_carving;
    const nlohmann::json& t = r.at("time_ms");
    out << "| " << runs.name << " | " << fixed(t.at("process").get<double>() / 1e3, 1) << " s | "
        << msCells(t, {"hull"}) << fixed(t.at("photo_carving").get<double>() / 1e3, 1) << " s | "
        << msCells(t, {"depth", "consistency", "voting", "silhouettes"})
        << fixed(r.at("carved_volume_m3").get<double>() * 1e6, 2) << " | "
        << fixed(r.at("reprojection_iou_after").at("min").get<double>(), 4) << " |\n";
  }
  out << "\n" << measurementsMarkdown(measurements);
  return out.str();
}

int reportBench(const ArgParser& parser, const std::vector<DatasetRuns>& all,
                const std::optional<SyntheticHullBench>& synthetic,
                const std::optional<EndToEndBench>& end_to_end) {
  nlohmann::json json = {{"datasets", nlohmann::json::array()},
                         {"measurements", measurementsJson(all)},
                         {"cpu", cpuModel()}};
  for (const DatasetRuns& runs : all) {
    nlohmann::json depths = nlohmann::json::array();
    for (const DepthRun& run : runs.depths) depths.push_back(depthJson(run));
    json["datasets"].push_back({{"name", runs.name},
                                {"views", runs.views},
                                {"depths", depths},
                                {"depth9_peak_mib", runs.peak_mib_depth9},
                                {"depth9_command_peak_mib", runs.command_peak_mib_depth9},
                                {"refinement_depth8", runs.refinement},
                                {"photo_carving_depth8", runs.photo_carving}});
  }
  std::string report = all.empty() ? "" : markdownReport(all, json["measurements"]);
  if (parser.has("write") && !all.empty()) {
    replaceMarkedSection(parser.get("write"), "bench-hull", report);
  }
  if (synthetic) {
    json["synthetic"] = syntheticJson(*synthetic);
    const std::string synthetic_report = syntheticMarkdown(*synthetic);
    if (parser.has("write")) {
      replaceMarkedSection(parser.get("write"), "bench-hull-synthetic", synthetic_report);
    }
    report += (report.empty() ? "" : "\n") + synthetic_report;
  }
  if (end_to_end) {
    json["end_to_end"] = endToEndJson(*end_to_end);
    const std::string end_to_end_report = endToEndMarkdown(*end_to_end);
    if (parser.has("write")) {
      replaceMarkedSection(parser.get("write"),
                           end_to_end->config.photographs ? "bench-hull-end-to-end-photographs"
                                                          : "bench-hull-end-to-end",
                           end_to_end_report);
    }
    report += (report.empty() ? "" : "\n") + end_to_end_report;
  }
  printResult(parser.flag("json"), json, report);
  return 0;
}

/// The synthetic case of --synthetic-views and --synthetic-size.
SyntheticHullCase syntheticCase(const ArgParser& parser) {
  SyntheticHullCase synthetic_case;
  sceneFromArgs(parser, "synthetic", &synthetic_case.views, &synthetic_case.width_px,
                &synthetic_case.height_px);
  return synthetic_case;
}

}  // namespace

int runBenchHull(const std::vector<std::string>& args) {
  ArgParser parser("bench-hull",
                   "Times the visual hull (distance transforms, LP box, octree, mesh) on dino and\n"
                   "temple at depths 7, 8, 9 against dense voxel carving at the same resolution\n"
                   "(and, at depth 8, refined with the matches of neighbouring views),\n"
                   "and on 120 rendered views of 4000x3000 at depth 9 with reduced and with\n"
                   "full-resolution distance maps.");
  parser.addOption("data", "DIR", "data root (default: $SIFT_HULL_DATA or ../shared/data)");
  parser.addOption("write", "MD", "replace the bench-hull section of this Markdown file");
  parser.addFlag("json", "print the result as one JSON object");
  parser.addFlag("synthetic-only", "run only the synthetic case (120 views of 4000x3000)");
  parser.addFlag("skip-synthetic", "leave the synthetic case out");
  addSceneOptions(&parser, "synthetic", "synthetic case", SyntheticHullCase().views,
                  SyntheticHullCase().width_px, SyntheticHullCase().height_px);
  parser.addFlag("end-to-end-only",
                 "run only the end-to-end case (whole hull processes on 120 JPEG masks of "
                 "4000x3000)");
  parser.addFlag("skip-end-to-end", "leave the end-to-end case out");
  addEndToEndOptions(&parser);
  if (!parser.parse(args)) return 0;
  if (parser.flag("synthetic-only") && parser.flag("skip-synthetic")) {
    throw UsageError("--synthetic-only and --skip-synthetic exclude each other");
  }
  if (parser.flag("end-to-end-only") && parser.flag("skip-end-to-end")) {
    throw UsageError("--end-to-end-only and --skip-end-to-end exclude each other");
  }
  if (parser.flag("end-to-end-only") && parser.flag("synthetic-only")) {
    throw UsageError("--end-to-end-only and --synthetic-only exclude each other");
  }
  const bool only_end_to_end = parser.flag("end-to-end-only");
  std::optional<EndToEndBench> end_to_end;
  if (!parser.flag("skip-end-to-end") && !parser.flag("synthetic-only")) {
    end_to_end = benchEndToEndHull(endToEndCaseFromArgs(parser));
  }
  const std::string root = parser.has("data") ? parser.get("data") : defaultDataRoot();

  std::vector<DatasetRuns> all;
  std::optional<SyntheticHullBench> synthetic;
  if (!parser.flag("skip-synthetic") && !only_end_to_end) {
    synthetic = benchSyntheticHull(syntheticCase(parser));
  }
  for (const HullDataset& dataset : hullDatasets()) {
    if (parser.flag("synthetic-only") || only_end_to_end) break;
    const std::string directory = root + "/" + dataset.directory;
    if (root.empty() || !std::filesystem::exists(directory)) {
      std::cerr << "bench-hull: skipping " << dataset.name << ": no " << directory << '\n';
      continue;
    }
    all.push_back(benchDataset(loadHullDataset(root, dataset), dataset.name));
    const nlohmann::json peak = hullCommandPeakMiB(directory, dataset);
    all.back().peak_mib_depth9 = peak.at("through_hull").get<double>();
    all.back().command_peak_mib_depth9 = peak.at("total").get<double>();
    all.back().refinement = refinementAtDepth8(directory, dataset);
    all.back().photo_carving = photoCarvingAtDepth8(directory, dataset);
  }
  return reportBench(parser, all, synthetic, end_to_end);
}

}  // namespace cli
}  // namespace sift_hull
