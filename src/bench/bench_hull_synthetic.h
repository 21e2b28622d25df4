#pragma once

#include <nlohmann/json.hpp>
#include <string>

#include "sift_hull/eval/hull_evaluation.h"
#include "sift_hull/hull/hull_pipeline.h"

namespace sift_hull {
namespace cli {

/// The synthetic case of bench-hull: many high-resolution views of the default sculpture.
struct SyntheticHullCase {
  int views = 120;
  int width_px = 4000;
  int height_px = 3000;
  int max_depth = 9;
  int runs = 3;  ///< hull runs per setting; the times are their medians
};

/// One setting of HullConfig::distance_reduction on the case.
struct SyntheticHullRun {
  int distance_reduction = 0;                                  ///< the setting (0: per view)
  int reduction_min = 0, reduction_max = 0;                    ///< the views' reductions
  double error_bound_mean_px = 0.0, error_bound_max_px = 0.0;  ///< the views' map error bounds
  HullTimings time;                                            ///< medians
  double peak_mib = 0.0;  ///< the process's peak resident memory during the runs (VmHWM)
  ReprojectionIoU iou;
  size_t surface_leaves = 0, mesh_faces = 0;
  bool watertight = false;
};

struct SyntheticHullBench {
  SyntheticHullCase config;
  double render_ms = 0.0;       ///< rendering the masks (run-length encoded as they are made)
  double masks_mib = 0.0;       ///< held by the run-length masks
  double input_peak_mib = 0.0;  ///< peak resident memory after rendering
  bool peak_reset = false;      ///< whether each run's peak could be measured alone
  SyntheticHullRun reduced;     ///< distance_reduction 0
  SyntheticHullRun full;        ///< distance_reduction 1, the baseline
};

/// Renders the case's masks (renderMask, each on OpenCV's threads) and runs the hull with the
/// chosen reductions and at full resolution, alternately, `config.runs` times each.
SyntheticHullBench benchSyntheticHull(const SyntheticHullCase& config);

nlohmann::json syntheticJson(const SyntheticHullBench& bench);
/// A Markdown paragraph and table of the case.
std::string syntheticMarkdown(const SyntheticHullBench& bench);

}  // namespace cli
}  // namespace sift_hull
