#pragma once

#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "args.h"

namespace sift_hull {
namespace cli {

/// bench-hull's end-to-end case: the renderer writes JPEG masks of many high-resolution views and a
/// par file, and the benchmark times whole `sift_hull hull` processes on them (what a user waits
/// for), with reduced decoding (the default) against full-resolution decoding
/// (--max-input-reduction 1), the baseline.
struct EndToEndCase {
  int views = 120;
  int width_px = 4000;
  int height_px = 3000;
  int max_depth = 9;
  int runs = 3;           ///< processes per setting; wall times and peaks are their medians
  int baseline_runs = 1;  ///< full-resolution processes (each takes tens of seconds)
  /// Photographs of the sculpture on a floor (JPEG, quality 92) instead of its masks: the
  /// processes segment them (the default silhouette method), reading them at a reduction.
  bool photographs = false;
  std::string executable;  ///< sift_hull; empty: the one beside this program
};

/// One setting's processes.
struct EndToEndRun {
  std::string setting;  ///< "reduced" or "full resolution"
  std::vector<std::string> arguments;
  std::vector<double> wall_s, peak_mib;  ///< each process's wall time and peak (ru_maxrss)
  nlohmann::json last;                   ///< the last process's JSON result
};

struct EndToEndBench {
  EndToEndCase config;
  double write_s = 0.0;    ///< rendering and writing the masks
  double files_mib = 0.0;  ///< the JPEG files on disk
  EndToEndRun reduced, full;
};

/// --end-to-end-views, --end-to-end-size, --end-to-end-baseline-runs and
/// --end-to-end-photographs, and the case they give.
void addEndToEndOptions(ArgParser* parser);
EndToEndCase endToEndCaseFromArgs(const ArgParser& parser);

/// Writes the case into a fresh temporary directory, runs the processes (the settings alternating
/// while both have runs left), removes the directory. Throws std::runtime_error when a process
/// fails.
EndToEndBench benchEndToEndHull(const EndToEndCase& config);

nlohmann::json endToEndJson(const EndToEndBench& bench);
/// A Markdown paragraph, table and measurements list of the case.
std::string endToEndMarkdown(const EndToEndBench& bench);

}  // namespace cli
}  // namespace sift_hull
