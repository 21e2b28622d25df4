// bench-hull's synthetic case: 120 views of 4000x3000 of the default sculpture at depth 9, hull
// with distance maps at the reduction each view allows against full-resolution maps.

#include "bench_hull_synthetic.h"

#include <malloc.h>

#include <algorithm>
#include <chrono>
#include <memory>
#include <optional>
#include <sstream>
#include <vector>

#include "bench_measure.h"
#include "bench_report.h"
#include "bench_scene.h"
#include "bench_timing.h"
#include "sift_hull/hull/reduced_distance_map.h"
#include "sift_hull/synthetic/mask_render.h"

namespace sift_hull {
namespace cli {
namespace {

using Clock = std::chrono::steady_clock;

/// The case's cameras and masks, each mask run-length encoded as soon as it is rendered.
HullInput renderCase(const SyntheticHullCase& config, double* masks_mib) {
  const BenchScene scene = benchScene(config.views, config.width_px, config.height_px);
  HullInput input;
  size_t bytes = 0;
  for (const CalibratedView& view : scene.cameras) {  // renderMask runs on OpenCV's threads
    input.names.push_back(view.name);
    input.cameras.push_back(view.camera);
    input.run_length_masks.emplace_back(renderMask(scene.shape, view.camera, scene.size));
  }
  for (const RunLengthMask& mask : input.run_length_masks) bytes += mask.memoryBytes();
  *masks_mib = bytes / (1024.0 * 1024.0);
  return input;
}

HullTimings medianTimings(const std::vector<HullTimings>& runs) {
  const auto field = [&](double HullTimings::*member) {
    std::vector<double> values;
    for (const HullTimings& run : runs) values.push_back(run.*member);
    return median(values);
  };
  HullTimings time;
  for (double HullTimings::*member :
       {&HullTimings::masks_ms, &HullTimings::distance_ms, &HullTimings::bbox_ms,
        &HullTimings::octree_ms, &HullTimings::mesh_ms, &HullTimings::total_ms}) {
    time.*member = field(member);
  }
  return time;
}

/// One setting's runs so far.
struct SettingRuns {
  HullConfig config;
  std::vector<HullTimings> times;
  double peak_mib = 0.0;
  std::optional<HullResult> last;
};

/// One more run of a setting, its peak resident memory measured alone when the kernel lets the
/// peak be reset (after returning freed heap memory to the system); its result kept only when
/// `keep` (no other result is alive during a run).
bool runOnce(const HullInput& input, bool keep, SettingRuns* runs) {
  malloc_trim(0);  // what the previous run freed leaves the resident set before the reset
  const bool reset = resetResidentPeak();
  runs->last.emplace(buildHull(input, runs->config));
  runs->times.push_back(runs->last->time);
  runs->peak_mib = std::max(runs->peak_mib, residentPeakMiB());
  if (!keep) runs->last.reset();
  return reset;
}

SyntheticHullRun summary(SettingRuns* runs) {
  SyntheticHullRun run;
  run.distance_reduction = runs->config.distance_reduction;
  run.peak_mib = runs->peak_mib;
  run.time = medianTimings(runs->times);
  const HullResult& last = *runs->last;
  run.reduction_min = kMaxDistanceReduction;
  for (const HullView& view : last.hull.views()) {
    run.reduction_min = std::min(run.reduction_min, view.distanceReduction());
    run.reduction_max = std::max(run.reduction_max, view.distanceReduction());
    run.error_bound_max_px =
        std::max(run.error_bound_max_px, static_cast<double>(view.distanceErrorBound_px()));
    run.error_bound_mean_px += view.distanceErrorBound_px() / last.hull.views().size();
  }
  run.surface_leaves = last.hull.stats().surface_leaves;
  run.mesh_faces = last.mesh.faces.size();
  run.watertight = last.mesh_check.watertight;
  run.iou = reprojectionIoU(last.mesh, last.hull.views());
  runs->last.reset();
  return run;
}

nlohmann::json runJson(const SyntheticHullRun& run) {
  return {{"distance_reduction", run.distance_reduction},
          {"reductions_used", {{"min", run.reduction_min}, {"max", run.reduction_max}}},
          {"error_bound_px", {{"mean", run.error_bound_mean_px}, {"max", run.error_bound_max_px}}},
          {"time_ms",
           {{"masks", run.time.masks_ms},
            {"bbox", run.time.bbox_ms},
            {"distance", run.time.distance_ms},
            {"octree", run.time.octree_ms},
            {"mesh", run.time.mesh_ms},
            {"total", run.time.total_ms}}},
          {"peak_mib", run.peak_mib},
          {"reprojection_iou", {{"min", run.iou.min}, {"mean", run.iou.mean}}},
          {"surface_leaves", run.surface_leaves},
          {"mesh_faces", run.mesh_faces},
          {"watertight", run.watertight}};
}

std::string runRow(const std::string& label, const SyntheticHullRun& run) {
  std::ostringstream out;
  out << "| " << label << " | " << run.reduction_min << ".." << run.reduction_max << " | "
      << fixed(run.error_bound_mean_px, 2) << " / " << fixed(run.error_bound_max_px, 2) << " | "
      << fixed(run.time.masks_ms, 0) << " | " << fixed(run.time.bbox_ms, 0) << " | "
      << fixed(run.time.distance_ms, 0) << " | " << fixed(run.time.octree_ms, 0) << " | "
      << fixed(run.time.mesh_ms, 0) << " | **" << fixed(run.time.total_ms, 0) << "** | "
      << fixed(run.peak_mib, 0) << " | " << fixed(run.iou.min, 4) << " / " << fixed(run.iou.mean, 4)
      << " | " << run.surface_leaves << " |\n";
  return out.str();
}

}  // namespace

SyntheticHullBench benchSyntheticHull(const SyntheticHullCase& config) {
  SyntheticHullBench bench;
  bench.config = config;
  const Clock::time_point start = Clock::now();
  const HullInput input = renderCase(config, &bench.masks_mib);
  bench.render_ms = millisecondsSince(start);
  bench.input_peak_mib = residentPeakMiB();
  // The settings alternate run by run, so that a load on the machine that comes and goes
  // weighs on both alike.
  SettingRuns reduced, full;
  reduced.config.max_depth = full.config.max_depth = config.max_depth;
  full.config.distance_reduction = 1;
  bench.peak_reset = true;
  const int runs = std::max(config.runs, 1);
  for (int i = 0; i < runs; ++i) {
    const bool keep = i + 1 == runs;
    bench.peak_reset = runOnce(input, keep, &reduced) && bench.peak_reset;
    if (keep) bench.reduced = summary(&reduced);  // frees its result
    bench.peak_reset = runOnce(input, keep, &full) && bench.peak_reset;
    if (keep) bench.full = summary(&full);
  }
  return bench;
}

nlohmann::json syntheticJson(const SyntheticHullBench& bench) {
  const SyntheticHullCase& c = bench.config;
  const double iou_difference = std::abs(bench.reduced.iou.mean - bench.full.iou.mean);
  return {{"views", c.views},
          {"image", {c.width_px, c.height_px}},
          {"max_depth", c.max_depth},
          {"runs", c.runs},
          {"cpu", cpuModel()},
          {"render_ms", bench.render_ms},
          {"run_length_masks_mib", bench.masks_mib},
          {"peak_measured_per_setting", bench.peak_reset},
          {"reduced", runJson(bench.reduced)},
          {"full_resolution", runJson(bench.full)},
          // What the targets of docs/BENCHMARKS.md are judged on, with the reduced maps.
          {"measurements",
           {{"hull_total_ms", bench.reduced.time.total_ms},
            {"peak_mib", bench.reduced.peak_mib},
            {"mean_iou_difference_to_full_resolution", iou_difference}}}};
}

std::string syntheticMarkdown(const SyntheticHullBench& bench) {
  const SyntheticHullCase& c = bench.config;
  std::ostringstream out;
  out << "Synthetic case: " << c.views << " views of " << c.width_px << "x" << c.height_px
      << " (the default sculpture, sphere layout, masks by `renderMask`, run-length encoded as "
      << "rendered: " << fixed(bench.masks_mib, 1) << " MiB for all, rendering "
      << fixed(bench.render_ms / 1000.0, 1) << " s), depth " << c.max_depth << ", median of "
      << c.runs << " runs per setting (the settings alternating), 2 threads, CPU " << cpuModel()
      << ". Times in ms; peak = VmHWM of the process during the runs of that setting, MiB"
      << (bench.peak_reset ? "" : " (could not be reset: the process's peak so far)") << ".\n\n"
      << "| distance maps | reduction | map error bound mean / max (px) | masks | bbox | distance "
         "| octree | mesh | total | peak | "
         "reproj. IoU min / mean | surface leaves |\n"
      << "| --- | --- | --- | --- | --- | --- | --- | --- | --- | --- | --- | --- |\n"
      << runRow("per view (`distance_reduction` 0)", bench.reduced)
      << runRow("full resolution (`distance_reduction` 1)", bench.full) << '\n'
      << measurementsMarkdown(syntheticJson(bench)["measurements"]);
  return out.str();
}

}  // namespace cli
}  // namespace sift_hull
