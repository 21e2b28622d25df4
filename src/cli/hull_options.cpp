#include "hull_options.h"

#include <algorithm>
#include <opencv2/imgproc.hpp>
#include <sstream>
#include <stdexcept>

#include "setting_options.h"
#include "sift_hull/hull/hull_config.h"
#include "sift_hull/hull/hull_octomap.h"
#include "sift_hull/hull/hull_pipeline.h"
#include "sift_hull/hull/hull_stream.h"
#include "sift_hull/hull/silhouette.h"
#include "sift_hull/io/reduced_images.h"
#include "sift_hull/io/view_list.h"
#include "silhouette_options.h"

namespace sift_hull {
namespace cli {
namespace {

nlohmann::json vectorJson(const Eigen::Vector3d& v) { return {v.x(), v.y(), v.z()}; }

std::vector<std::string> splitList(const std::string& text) {
  std::vector<std::string> items;
  std::istringstream in(text);
  std::string item;
  while (std::getline(in, item, ',')) {
    if (item.empty()) throw UsageError("--views: an empty name in '" + text + "'");
    items.push_back(item);
  }
  if (items.empty()) throw UsageError("--views names no view");
  return items;
}

std::vector<std::string> viewNamesFromArgs(const ArgParser& parser) {
  if (parser.has("views") && parser.has("views-file")) {
    throw UsageError("give --views or --views-file, not both");
  }
  if (parser.has("views")) return splitList(parser.get("views"));
  if (parser.has("views-file")) {
    std::vector<std::string> names = readViewList(parser.get("views-file"));
    if (names.empty()) throw std::runtime_error(parser.get("views-file") + ": names no view");
    return names;
  }
  return {};
}

}  // namespace

void addViewSetOptions(ArgParser* parser) {
  parser->addOption("calib", "FILE|DIR",
                    "Middlebury par file, projection list, COLMAP sparse model directory, LLFF "
                    "poses_bounds.npy, NeRF transforms.json, or IDR / NeuS cameras.npz (or a "
                    "directory holding it; its views are the sorted images of --images)");
  parser->addOption("images", "DIR", "directory of the images the calibration names");
  addSilhouetteOptions(parser);
  parser->addOption("views", "LIST", "comma-separated image names to use (default: all)");
  parser->addOption("views-file", "FILE", "file of image names to use, one per line");
}

HullInput viewSetFromArgs(const ArgParser& parser) {
  const std::string masks = parser.has("silhouettes") ? parser.get("silhouettes") : "";
  return loadHullInput(parser.get("calib"), parser.get("images"), masks,
                       silhouetteConfigFromArgs(parser), viewNamesFromArgs(parser));
}

HullInput runLengthViewSetFromArgs(const ArgParser& parser, ViewSilhouettes* report) {
  const std::string masks = parser.has("silhouettes") ? parser.get("silhouettes") : "";
  return loadRunLengthHullInput(parser.get("calib"), parser.get("images"), masks,
                                silhouetteConfigFromArgs(parser), viewNamesFromArgs(parser),
                                report);
}

void addInputReductionOption(ArgParser* parser) {
  parser->addOption("max-input-reduction", "N",
                    "largest reduction (1, 2, 4 or 8) at which mask files (--silhouettes) are "
                    "decoded, each view's following from its finest voxel's footprint, and at "
                    "which photographs are segmented; 1: full resolution",
                    "8");
}

int maxInputReductionFromArgs(const ArgParser& parser) {
  const int most = parser.getInt("max-input-reduction");
  if (!isDecodableReduction(most)) {
    throw UsageError("--max-input-reduction must be 1, 2, 4 or 8, not " + std::to_string(most));
  }
  const bool photographs = parser.flag("refine-with-matches") || parser.flag("photo-carve") ||
                           parser.has("holdout-view");
  return photographs ? 1 : most;
}

HullInput reducedViewSetFromArgs(
    const ArgParser& parser, const HullConfig& config, const std::optional<Box3d>& box,
    int max_reduction, ViewSilhouettes* report,
    const std::function<void(size_t read, size_t total)>& on_view_read) {
  if (!parser.has("silhouettes")) {
    return loadReducedPhotoHullInput(parser.get("calib"), parser.get("images"),
                                     viewNamesFromArgs(parser), silhouetteConfigFromArgs(parser),
                                     config, max_reduction, report, on_view_read);
  }
  return loadReducedHullInput(parser.get("calib"), parser.get("images"), parser.get("silhouettes"),
                              viewNamesFromArgs(parser), config, box, max_reduction, on_view_read);
}

cv::Mat fullSizeMask(const HullInput& input, size_t view) {
  const cv::Mat mask = input.mask(view);
  const int reduction = input.reduction(view);
  if (reduction == 1) return mask;
  cv::Mat enlarged;
  cv::resize(mask, enlarged, cv::Size(mask.cols * reduction, mask.rows * reduction), 0.0, 0.0,
             cv::INTER_LINEAR);
  return enlarged(cv::Rect(cv::Point(0, 0), input.image_sizes.at(view))) > 127;
}

nlohmann::json inputReductionJson(const HullInput& input) {
  int smallest = 1, largest = 1;
  if (!input.reductions.empty()) {
    smallest = *std::min_element(input.reductions.begin(), input.reductions.end());
    largest = *std::max_element(input.reductions.begin(), input.reductions.end());
  }
  nlohmann::json json = {{"min", smallest}, {"max", largest}};
  if (!input.image_sizes.empty()) {
    json["image_size"] = {input.image_sizes.front().width, input.image_sizes.front().height};
  }
  return json;
}

void addHullOptions(ArgParser* parser) {
  addSettingOptions(parser, settingsOf<HullConfig>());
  parser->addOption("box", "XMIN,YMIN,ZMIN,XMAX,YMAX,ZMAX",
                    "bounding box in world units instead of solving the LP; or an OctoMap file "
                    "written by --out-octree or the hull node's ~save: the box it was carved in");
}

HullConfig hullConfigFromArgs(const ArgParser& parser) {
  HullConfig config;
  settingsFromArgs(parser, settingsOf<HullConfig>(), &config);
  validateOptions(config);
  return config;
}

std::optional<Box3d> boxFromArgs(const ArgParser& parser) {
  if (!parser.has("box")) return std::nullopt;
  const std::string value = parser.get("box");
  if (value.find(',') == std::string::npos) {  // a file: the box in its header
    std::optional<Box3d> carved_in = readCarvingBox(value);
    if (!carved_in) {
      throw std::runtime_error(value +
                               ": its header has no carving_box line (OctoMap files of "
                               "sift_hull hull --out-octree and the hull node's ~save have one)");
    }
    return carved_in;
  }
  const Setting<HullStreamConfig>* box = settingsOf<HullStreamConfig>().find("box");
  HullStreamConfig config;
  try {
    box->set(&config, optionValue(parser, box->info));
  } catch (const std::invalid_argument& error) {
    throw UsageError("--" + std::string(error.what()));
  }
  if (!config.box) throw UsageError("--box expects six comma-separated numbers");
  return config.box;
}

namespace {

/// The distance reductions the views used: smallest and largest.
nlohmann::json distanceReductionsJson(const std::vector<HullView>& views) {
  int smallest = 0, largest = 0;
  for (const HullView& view : views) {
    const int reduction = view.distanceReduction();
    smallest = smallest == 0 ? reduction : std::min(smallest, reduction);
    largest = std::max(largest, reduction);
  }
  return {{"min", smallest}, {"max", largest}};
}

}  // namespace

nlohmann::json hullJson(const HullResult& result, size_t occupied_leaves,
                        const ReprojectionIoU& iou) {
  const HullTimings& time = result.time;
  return {{"views", result.hull.views().size()},
          {"bbox", {{"min", vectorJson(result.box.min_W)}, {"max", vectorJson(result.box.max_W)}}},
          {"max_depth", result.hull.cube().depth},
          {"distance_reduction", distanceReductionsJson(result.hull.views())},
          {"resolution_m", result.hull.cube().resolution_m},
          {"occupied_leaves", occupied_leaves},
          {"mesh",
           {{"vertices", result.mesh.vertices_W.size()},
            {"faces", result.mesh.faces.size()},
            {"watertight", result.mesh_check.watertight}}},
          {"time_ms",
           {{"distance", time.distance_ms},
            {"bbox", time.bbox_ms},
            {"masks", time.masks_ms},
            {"octree", time.octree_ms},
            {"mesh", time.mesh_ms},
            {"total", time.total_ms}}},
          {"reprojection_iou",
           {{"min", iou.min},
            {"mean", iou.mean},
            {"per_view", iou.per_view},
            {"sample_step_px", iou.sample_step_px}}}};
}

const std::vector<HullDataset>& hullDatasets() {
  // Temple at 0.19: mean reprojection IoU 0.956 at depth 7; at 0.25, 0.982.
  static const std::vector<HullDataset> datasets = {
      {"dino", "middlebury_mvs_dinoSparseRing", "dinoSR_par.txt",
       "dinoSR_good_silhouette_images.txt", 0.19},
      {"temple", "middlebury_mvs_templeSparseRing", "templeSR_par.txt", "", 0.25},
  };
  return datasets;
}

HullInput loadHullDataset(const std::string& root, const HullDataset& dataset) {
  const std::string directory = root + "/" + dataset.directory;
  const std::vector<std::string> names = dataset.view_list.empty()
                                             ? std::vector<std::string>{}
                                             : readViewList(directory + "/" + dataset.view_list);
  SilhouetteConfig recipe;  // the Middlebury recipe at the set's threshold, as runs compare
  recipe.silhouette_method = "threshold";
  recipe.threshold = dataset.threshold;
  return loadHullInput(directory + "/" + dataset.calibration, directory, "", recipe, names);
}

}  // namespace cli
}  // namespace sift_hull
