// bench-hull's end-to-end case (bench_hull_end_to_end.h): JPEG masks written by the renderer,
// whole `sift_hull hull` processes timed with their peak memory.

#include "bench_hull_end_to_end.h"

#include <sys/resource.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <opencv2/core/utility.hpp>
#include <opencv2/imgcodecs.hpp>
#include <sstream>
#include <stdexcept>

#include "args.h"
#include "bench_measure.h"
#include "bench_report.h"
#include "bench_scene.h"
#include "commands.h"
#include "sift_hull/io/calibration.h"
#include "sift_hull/process.h"
#include "sift_hull/synthetic/mask_render.h"
#include "sift_hull/synthetic/scene.h"

namespace sift_hull {
namespace cli {
namespace {

namespace fs = std::filesystem;

/// The default sculpture on the sphere layout: each view's mask as a JPEG (quality 95, as cameras
/// and tools write them), or its photograph on a floor (quality 92), named view_NNNN.jpg, and
/// scene_par.txt. Returns the files' MiB.
double writeCase(const EndToEndCase& config, const fs::path& directory) {
  BenchScene scene = benchScene(config.views, config.width_px, config.height_px,
                                config.photographs ? "floor" : "none");
  double bytes = 0.0;
  for (CalibratedView& view : scene.cameras) {  // the renderers run on OpenCV's threads
    view.name = fs::path(view.name).stem().string() + ".jpg";
    const std::string path = (directory / view.name).string();
    const bool written =
        config.photographs
            ? cv::imwrite(path,
                          renderView(scene.shape, view, scene.size, 1, "black", "floor").image,
                          {cv::IMWRITE_JPEG_QUALITY, 92})
            : cv::imwrite(path, renderMask(scene.shape, view.camera, scene.size),
                          {cv::IMWRITE_JPEG_QUALITY, 95});
    if (!written) throw std::runtime_error(path + ": cannot write the image");
    bytes += static_cast<double>(fs::file_size(path));
  }
  writeMiddleburyPar((directory / "scene_par.txt").string(), scene.cameras);
  return bytes / (1024.0 * 1024.0);
}

/// Runs `executable arguments...` with its stdout into `output`; its wall time in seconds and
/// peak resident memory in MiB. Throws std::runtime_error when it cannot start or fails.
void runProcess(const std::string& executable, const std::vector<std::string>& arguments,
                const fs::path& output, double* wall_s, double* peak_mib) {
  std::vector<std::string> command = {executable};
  command.insert(command.end(), arguments.begin(), arguments.end());
  const auto start = std::chrono::steady_clock::now();
  const pid_t child = startProgram(command, output.string(), ProgramOutput::kStdoutToFile);
  if (child < 0) throw std::runtime_error(executable + ": cannot start it");
  int status = 0;
  rusage usage{};
  if (wait4(child, &status, 0, &usage) != child) throw std::runtime_error("wait4 failed");
  *wall_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  *peak_mib = usage.ru_maxrss / 1024.0;  // KiB on Linux
  if (!WIFEXITED(status) || WEXITSTATUS(status) != 0) {
    throw std::runtime_error(executable + " hull failed (status " + std::to_string(status) +
                             ") on the end-to-end case");
  }
}

void runOnce(const std::string& executable, const fs::path& directory, EndToEndRun* run) {
  const fs::path output = directory / "result.json";
  double wall_s = 0.0, peak_mib = 0.0;
  runProcess(executable, run->arguments, output, &wall_s, &peak_mib);
  run->wall_s.push_back(wall_s);
  run->peak_mib.push_back(peak_mib);
  std::ifstream in(output);
  run->last = nlohmann::json::parse(in);
}

std::string siblingExecutable() {
  return (fs::read_symlink("/proc/self/exe").parent_path() / "sift_hull").string();
}

nlohmann::json runJson(const EndToEndRun& run) {
  const nlohmann::json& last = run.last;
  return {{"setting", run.setting},
          {"arguments", run.arguments},
          {"wall_s", run.wall_s},
          {"peak_mib", run.peak_mib},
          {"median_wall_s", run.wall_s.empty() ? 0.0 : median(run.wall_s)},
          {"median_peak_mib", run.peak_mib.empty() ? 0.0 : median(run.peak_mib)},
          {"time_ms", last.value("time_ms", nlohmann::json::object())},
          {"input_reduction", last.value("input_reduction", nlohmann::json::object())},
          {"reprojection_iou",
           {{"min", last.at("reprojection_iou").at("min")},
            {"mean", last.at("reprojection_iou").at("mean")}}},
          {"mesh_faces", last.at("mesh").at("faces")}};
}

std::string runRow(const EndToEndRun& run) {
  const nlohmann::json json = runJson(run);
  std::ostringstream out;
  out << "| " << run.setting << " | " << json["input_reduction"].value("min", 1) << ".."
      << json["input_reduction"].value("max", 1) << " | **"
      << fixed(json["median_wall_s"].get<double>(), 2) << "** | "
      << fixed(json["median_peak_mib"].get<double>(), 0) << " | "
      << fixed(json["time_ms"].value("total", 0.0), 0) << " | "
      << fixed(json["time_ms"].value("distance", 0.0), 0) << " | "
      << fixed(json["reprojection_iou"]["min"].get<double>(), 4) << " / "
      << fixed(json["reprojection_iou"]["mean"].get<double>(), 4) << " | " << json["mesh_faces"]
      << " |\n";
  return out.str();
}

}  // namespace

void addEndToEndOptions(ArgParser* parser) {
  addSceneOptions(parser, "end-to-end", "end-to-end case", EndToEndCase().views,
                  EndToEndCase().width_px, EndToEndCase().height_px);
  parser->addOption("end-to-end-baseline-runs", "N",
                    "full-resolution processes of the end-to-end case (0 leaves the baseline out)",
                    std::to_string(EndToEndCase().baseline_runs));
  parser->addFlag("end-to-end-photographs",
                  "photographs of the sculpture on a floor instead of its masks: the processes "
                  "segment them (the default silhouette method)");
}

EndToEndCase endToEndCaseFromArgs(const ArgParser& parser) {
  EndToEndCase end_to_end;
  sceneFromArgs(parser, "end-to-end", &end_to_end.views, &end_to_end.width_px,
                &end_to_end.height_px);
  end_to_end.baseline_runs = parser.getInt("end-to-end-baseline-runs");
  if (end_to_end.baseline_runs < 0) {
    throw UsageError("--end-to-end-baseline-runs must not be negative");
  }
  end_to_end.photographs = parser.flag("end-to-end-photographs");
  return end_to_end;
}

EndToEndBench benchEndToEndHull(const EndToEndCase& config) {
  EndToEndBench bench;
  bench.config = config;
  const std::string executable =
      config.executable.empty() ? siblingExecutable() : config.executable;
  std::string pattern = (fs::temp_directory_path() / "sift_hull_end_to_end_XXXXXX").string();
  if (mkdtemp(pattern.data()) == nullptr) throw std::runtime_error("cannot make a directory");
  const fs::path directory = pattern;
  try {
    const auto start = std::chrono::steady_clock::now();
    bench.files_mib = writeCase(config, directory);
    bench.write_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    std::vector<std::string> common = {"hull",
                                       "--calib",
                                       (directory / "scene_par.txt").string(),
                                       "--images",
                                       directory.string(),
                                       "--max-depth",
                                       std::to_string(config.max_depth),
                                       "--json"};
    if (!config.photographs) common.insert(common.end(), {"--silhouettes", directory.string()});
    bench.reduced.setting = "reduced decoding (default)";
    bench.reduced.arguments = common;
    bench.full.setting = "full resolution (`--max-input-reduction 1`)";
    bench.full.arguments = common;
    bench.full.arguments.insert(bench.full.arguments.end(), {"--max-input-reduction", "1"});
    for (int i = 0; i < std::max(config.runs, config.baseline_runs); ++i) {
      if (i < config.runs) runOnce(executable, directory, &bench.reduced);
      if (i < config.baseline_runs) runOnce(executable, directory, &bench.full);
    }
  } catch (...) {
    fs::remove_all(directory);
    throw;
  }
  fs::remove_all(directory);
  return bench;
}

nlohmann::json endToEndJson(const EndToEndBench& bench) {
  const EndToEndCase& c = bench.config;
  nlohmann::json json = {{"views", c.views},
                         {"image", {c.width_px, c.height_px}},
                         {"max_depth", c.max_depth},
                         {"cpu", cpuModel()},
                         {"write_s", bench.write_s},
                         {"input", c.photographs ? "photographs" : "masks"},
                         {"jpeg_files_mib", bench.files_mib},
                         {"reduced", runJson(bench.reduced)}};
  nlohmann::json measurements = {{"end_to_end_wall_s", json["reduced"]["median_wall_s"]},
                                 {"end_to_end_peak_mib", json["reduced"]["median_peak_mib"]}};
  if (!bench.full.wall_s.empty()) {
    json["full_resolution"] = runJson(bench.full);
    measurements["mean_iou_difference_to_full_resolution"] =
        std::abs(json["reduced"]["reprojection_iou"]["mean"].get<double>() -
                 json["full_resolution"]["reprojection_iou"]["mean"].get<double>());
  }
  json["measurements"] = measurements;
  return json;
}

std::string endToEndMarkdown(const EndToEndBench& bench) {
  const EndToEndCase& c = bench.config;
  std::ostringstream out;
  out << "End-to-end case: " << c.views
      << (c.photographs ? " JPEG photographs of " : " JPEG masks of ") << c.width_px << "x"
      << c.height_px
      << (c.photographs
              ? " (the default sculpture on a floor, sphere layout, `renderView` written at "
                "quality 92: "
              : " (the default sculpture, sphere layout, `renderMask` written at quality 95: ")
      << fixed(bench.files_mib, 1) << " MiB, written in " << fixed(bench.write_s, 1)
      << " s), `sift_hull hull --calib scene_par.txt --images DIR "
      << (c.photographs ? "" : "--silhouettes DIR ") << "--max-depth " << c.max_depth
      << " --json` as a child process; wall time and peak resident memory "
      << "(ru_maxrss) of the whole process, medians of " << bench.reduced.wall_s.size()
      << " processes with reduced decoding and " << bench.full.wall_s.size()
      << " at full resolution, 2 cores, CPU " << cpuModel()
      << ". `hull` = the JSON's `time_ms.total` (distance maps, box, octree, mesh), ms.\n\n"
      << "| decoding | input reduction | wall (s) | peak (MiB) | hull | distance | reproj. IoU min "
         "/ "
         "mean | mesh faces |\n"
      << "| --- | --- | --- | --- | --- | --- | --- | --- |\n"
      << runRow(bench.reduced);
  if (!bench.full.wall_s.empty()) out << runRow(bench.full);
  out << '\n' << measurementsMarkdown(endToEndJson(bench)["measurements"]);
  return out.str();
}

}  // namespace cli
}  // namespace sift_hull
