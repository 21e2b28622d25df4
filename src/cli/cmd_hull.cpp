#include <octomap/OcTree.h>
#include <unistd.h>

#include <chrono>
#include <iomanip>
#include <iostream>
#include <mutex>
#include <opencv2/imgcodecs.hpp>
#include <sstream>

#include "args.h"
#include "bench_timing.h"
#include "commands.h"
#include "hull_options.h"
#include "refine_options.h"
#include "sift_hull/eval/mesh_render.h"
#include "sift_hull/geometry/camera_set.h"
#include "sift_hull/hull/hull_config.h"
#include "sift_hull/hull/hull_octomap.h"
#include "sift_hull/hull/hull_pipeline.h"
#include "sift_hull/hull/silhouette.h"
#include "sift_hull/io/ply.h"
#include "sift_hull/mvs/mesh_colour.h"
#include "silhouette_options.h"

namespace sift_hull {
namespace cli {
namespace {

void writeRender(const std::string& path, const TriangleMesh& mesh) {
  if (!cv::imwrite(path, renderTurntable(mesh, 4, cv::Size(480, 480)))) {
    throw std::runtime_error(path + ": cannot write the image");
  }
}

/// PATH.png -> PATH_before.png: the silhouettes' hull beside the refined one.
std::string beforePath(const std::string& path) {
  const size_t dot = path.find_last_of('.');
  const size_t slash = path.find_last_of('/');
  if (dot == std::string::npos || (slash != std::string::npos && dot < slash)) {
    return path + "_before";
  }
  return path.substr(0, dot) + "_before" + path.substr(dot);
}

/// `octree` is the hull's OctoMap when --out-octree or --out-color-octree asks for it.
void writeOutputs(const ArgParser& parser, const HullResult& result,
                  const octomap::OcTree* octree) {
  if (parser.has("out-mesh")) writePly(parser.get("out-mesh"), result.mesh);
  if (parser.has("out-octree")) writeOctomap(*octree, parser.get("out-octree"), result.box);
  if (parser.has("out-color-octree")) {
    writeColourOctomap(*colourOctomap(*octree, result.mesh), parser.get("out-color-octree"));
  }
  if (parser.has("out-render")) writeRender(parser.get("out-render"), result.mesh);
}

/// A result that cannot be right: an error, or with --allow-poor a warning on stderr and in the
/// JSON's `warnings`.
/// `clear_line`: a progress line may stand on stderr; each warning clears it first.
class PoorResults {
 public:
  PoorResults(bool allow, bool clear_line) : allow_(allow), clear_line_(clear_line) {}
  void report(const std::string& reason) {
    if (!allow_) throw std::runtime_error(reason + " (--allow-poor accepts it)");
    warn(reason);
  }
  /// A warning whatever --allow-poor says (a suspect view, for instance).
  void warn(const std::string& reason) {
    std::cerr << (clear_line_ ? "\r\033[K" : "") << "sift_hull hull: warning: " << reason << '\n';
    warnings_.push_back(reason);
  }
  const std::vector<std::string>& warnings() const { return warnings_; }

 private:
  bool allow_, clear_line_;
  std::vector<std::string> warnings_;
};

/// The stage a run has reached, on stderr when it is a terminal and the result is not JSON: one
/// line rewritten in place, with the seconds since the start; cleared at the end. Counts (views
/// read) may come from several threads; they are shown at most ten times a second.
class Progress {
 public:
  explicit Progress(bool wanted) : shown_(wanted && isatty(STDERR_FILENO) == 1) {}
  Progress(const Progress&) = delete;
  Progress& operator=(const Progress&) = delete;
  /// An error on its way out clears the line before it is printed.
  ~Progress() { done(); }
  bool shown() const { return shown_; }
  void stage(const std::string& text) {
    std::lock_guard<std::mutex> lock(mutex_);
    if (shown_) show(text);
  }
  void count(const std::string& text, size_t done, size_t total) {
    std::lock_guard<std::mutex> lock(mutex_);
    if (!shown_) return;
    if (done < total && Clock::now() - last_ < std::chrono::milliseconds(100)) return;
    show(text + " " + std::to_string(done) + " of " + std::to_string(total));
  }
  void done() {
    std::lock_guard<std::mutex> lock(mutex_);
    if (shown_) std::cerr << "\r\033[K" << std::flush;
    shown_ = false;
  }

 private:
  using Clock = std::chrono::steady_clock;
  void show(const std::string& text) {
    last_ = Clock::now();
    const double seconds = std::chrono::duration<double>(last_ - start_).count();
    std::ostringstream line;
    line << "sift_hull hull: " << std::fixed << std::setprecision(1) << seconds << " s, " << text;
    std::cerr << "\r\033[K" << line.str() << std::flush;
  }
  bool shown_;
  std::mutex mutex_;
  Clock::time_point start_ = Clock::now(), last_ = start_;
};

/// The reprojection IoU compares at most this many pixels of a view (every k-th pixel of every
/// k-th row of a larger mask).
constexpr size_t kMaxIoUSamplesPerView = size_t{1} << 20;

/// Largest box edge over the cameras' mutual distance (largest distance between two centres).
constexpr double kMaxBoxEdgeOverCameraDistance = 100.0;
/// Below this mean reprojection IoU the hull does not explain the silhouettes.
constexpr double kMinMeanIoU = 0.5;

std::string joined(const std::vector<std::string>& names) {
  std::string list;
  for (const std::string& name : names) list += (list.empty() ? "'" : ", '") + name + "'";
  return list;
}

/// A --box no camera sees in front of it, or far larger than the camera set.
void checkBox(const Box3d& box, const HullInput& input, PoorResults* poor) {
  const std::vector<std::string> behind = viewsSeeingBoxBehind(box, input.cameras, input.names);
  if (!input.cameras.empty() && behind.size() == input.cameras.size()) {
    poor->report("no camera sees the --box in front of it: its centre is behind " + joined(behind));
  }
  const double distance = camerasMutualDistance(input.cameras);
  const double edge = box.size().maxCoeff();
  if (distance > 0.0 && edge > kMaxBoxEdgeOverCameraDistance * distance) {
    std::ostringstream text;
    text << "the --box's longest edge, " << edge << ", exceeds " << kMaxBoxEdgeOverCameraDistance
         << " times the cameras' mutual distance (largest distance between two camera centres), "
         << distance;
    poor->report(text.str());
  }
}

/// A mesh with no faces or a mean reprojection IoU below kMinMeanIoU.
void checkResult(const HullResult& result, const ReprojectionIoU& iou, PoorResults* poor) {
  if (result.mesh.faces.empty()) {
    poor->report("the mesh has no faces: nothing is seen inside every silhouette");
  }
  if (!(iou.mean >= kMinMeanIoU)) {
    std::ostringstream text;
    text << "the mean reprojection IoU is " << iou.mean << ", below " << kMinMeanIoU
         << ": the hull does not explain the silhouettes";
    poor->report(text.str());
  }
}

std::string hullText(const nlohmann::json& result) {
  std::ostringstream text;
  text << result["views"] << " views, depth " << result["max_depth"] << " (voxel "
       << result["resolution_m"] << "), box " << result["bbox"]["min"] << " .. "
       << result["bbox"]["max"] << "\noccupied leaves " << result["occupied_leaves"] << ", mesh "
       << result["mesh"]["vertices"] << " vertices, " << result["mesh"]["faces"]
       << " faces, watertight " << result["mesh"]["watertight"] << "\ntime (ms) "
       << result["time_ms"].dump() << "\nreprojection IoU min " << result["reprojection_iou"]["min"]
       << ", mean " << result["reprojection_iou"]["mean"] << '\n';
  if (result.contains("points")) {
    text << "refined with matches: " << result["points"]["kept"] << " surface points of "
         << result["points"]["triangulated"] << " triangulated (" << result["points"]["pairs"]
         << " pairs), " << result["free_voxels"] << " free voxels, carved "
         << result["carved_volume_m3"] << " m^3\n";
  }
  if (result.contains("silhouettes")) {
    const auto& found = result["silhouettes"];
    text << "silhouettes from the views together in " << found["time_ms"]
         << " ms; support cut: " << found["support_cut_fraction"] << " of the coarse hull, up to "
         << found["support_cut_height"] << " above its bottom\n";
  }
  if (result.contains("volume_iou_vs_truth")) {
    text << "volume IoU against the true solid " << result["volume_iou_vs_truth"]["before"]
         << (result.contains("points") ? " before, " : "");
    if (result.contains("points")) {
      text << result["volume_iou_vs_truth"]["after"] << " after; false carving "
           << result["false_carved_fraction"] << " of the true volume";
    }
    text << '\n';
  }
  return text.str();
}

}  // namespace

int runHull(const std::vector<std::string>& args) {
  ArgParser parser("hull",
                   "Visual hull of calibrated silhouettes: bounding box by linear programming,\n"
                   "octree carving with signed distances, marching cubes.");
  addViewSetOptions(&parser);
  addHullOptions(&parser);
  addInputReductionOption(&parser);
  parser.addOption("out-mesh", "PLY",
                   "write the mesh (binary PLY, world coordinates; with --images, each vertex "
                   "coloured by the views that see it)");
  parser.addOption("out-octree", "BT", "write the OctoMap (.bt)");
  addSilhouetteOutputOption(&parser);
  parser.addOption("out-render", "PNG",
                   "write shaded renderings of the mesh (with --refine-with-matches also those of "
                   "the silhouettes' hull, as PNG with _before before the extension)");
  addRefineOptions(&parser);
  parser.addOption("out-color-octree", "OT",
                   "write the octree as OctoMap's ColorOcTree (.ot), its surface voxels coloured "
                   "by the views (needs --images)");
  parser.addOption("holdout-view", "NAME",
                   "build everything without this view, render the model coloured by the others "
                   "into it, and report the colour error against its photograph inside its "
                   "silhouette, for the silhouettes' hull and for the refined model");
  parser.addFlag("json", "print the result as one JSON object");
  parser.addFlag("allow-poor",
                 "warn instead of failing on a result that cannot be right (no faces, mean IoU "
                 "below 0.5, a --box behind every camera or over 100x the cameras' distance)");
  if (!parser.parse(args)) return 0;

  const HullConfig config = hullConfigFromArgs(parser);
  checkRefineOptions(parser);
  if (parser.has("out-color-octree") && !parser.has("images")) {
    throw UsageError("--out-color-octree needs --images");
  }
  Progress progress(!parser.flag("json"));
  PoorResults poor(parser.flag("allow-poor"), progress.shown());
  ViewSilhouettes found;
  const std::optional<Box3d> box = boxFromArgs(parser);
  const int max_reduction = maxInputReductionFromArgs(parser);
  progress.stage("reading the views");
  const auto on_view_read = [&](size_t read, size_t total) {
    progress.count("views read", read, total);
  };
  HullInput input =
      max_reduction > 1 || !parser.has("silhouettes")
          ? reducedViewSetFromArgs(parser, config, box, max_reduction, &found, on_view_read)
          : runLengthViewSetFromArgs(parser, &found);
  progress.stage("read " + std::to_string(input.viewCount()) + " views");
  writeSilhouettesFromArgs(parser, input.names, [&](size_t i) { return fullSizeMask(input, i); });
  writeViewPriorsFromArgs(parser, input.names, found);
  for (const std::string& warning : found.warnings) poor.warn(warning);
  const std::optional<HeldOutView> held_out = holdOutView(parser, &input);
  for (const std::string& warning :
       runLengthSilhouetteWarnings(input.names, input.run_length_masks))
    poor.warn(warning);
  if (box) checkBox(*box, input, &poor);
  HullResult result = buildHull(input, config, box, [&](const std::string& stage) {
    progress.stage(
        stage == "octree" ? "carving the octree to depth " + std::to_string(config.max_depth)
        : stage == "mesh" ? "marching cubes"
                          : stage + " of " + std::to_string(input.viewCount()) + " views");
  });
  if ((parser.flag("refine-with-matches") || parser.flag("photo-carve")) &&
      parser.has("out-render")) {
    writeRender(beforePath(parser.get("out-render")), result.mesh);
  }
  nlohmann::json holdout;
  const int threads = result.hull.config().threads;
  if (held_out)
    holdout = {{"name", held_out->name},
               {"hull", heldOutError(parser, input, *held_out, result.mesh, threads)}};
  nlohmann::json refined = refineWithMatches(parser, input, &result);
  refined.update(colourMesh(parser, input, &result));
  if (held_out) {
    holdout["refined"] = heldOutError(parser, input, *held_out, result.mesh, threads);
    refined["holdout_view"] = holdout;
  }
  const double hull_peak_mib = peakMemoryMiB();
  // OctoMap's own nodes only for the files that need them; the count from the compact map.
  std::unique_ptr<octomap::OcTree> octree;
  if (parser.has("out-octree") || parser.has("out-color-octree")) {
    progress.stage("converting the octree to OctoMap");
    octree = toOctomap(result.hull);
  }
  const size_t occupied_leaves = compactOctomap(result.hull).occupied_centres_W.size();
  progress.stage("checking the mesh against every view");
  const ReprojectionIoU iou = reprojectionIoU(result.mesh, result.hull.views(), threads,
                                              kMaxIoUSamplesPerView, result.mesh_check.watertight);
  for (const std::string& warning : disagreeingViewWarnings(input.names, iou.per_view)) {
    poor.warn(warning);
  }
  checkResult(result, iou, &poor);
  progress.stage("writing");
  writeOutputs(parser, result, octree.get());
  nlohmann::json json = hullJson(result, occupied_leaves, iou);
  json["input_reduction"] = inputReductionJson(input);
  json.update(refined);
  if (found.ball_centre_W || !found.background_reason.empty()) {
    json["silhouettes"] = viewSilhouettesJson(found);
  }
  json["warnings"] = poor.warnings();
  json["peak_memory_mib"] = {{"through_hull", hull_peak_mib}, {"total", peakMemoryMiB()}};
  progress.done();
  printResult(parser.flag("json"), json, hullText(json));
  return 0;
}

}  // namespace cli
}  // namespace sift_hull
