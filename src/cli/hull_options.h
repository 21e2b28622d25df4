#pragma once

#include <nlohmann/json.hpp>
#include <optional>
#include <string>
#include <vector>

#include "args.h"
#include "sift_hull/eval/hull_evaluation.h"
#include "sift_hull/hull/hull_config.h"
#include "sift_hull/hull/hull_pipeline.h"
#include "sift_hull/hull/view_silhouettes.h"

namespace sift_hull {
namespace cli {

/// --calib, --images, the silhouette options and --views / --views-file: a calibrated view set
/// with silhouettes, as `hull` and `bag` take it.
void addViewSetOptions(ArgParser* parser);
/// The views those options name (all when neither --views nor --views-file is given).
HullInput viewSetFromArgs(const ArgParser& parser);
/// The same views with their silhouettes run-length encoded (HullInput::run_length_masks).
HullInput runLengthViewSetFromArgs(const ArgParser& parser, ViewSilhouettes* report = nullptr);

/// --max-depth, --carve-outside-image, --distance-slack-px, --distance-reduction, --threads, with
/// HullConfig's defaults.
void addHullOptions(ArgParser* parser);
HullConfig hullConfigFromArgs(const ArgParser& parser);

/// --box "XMIN,YMIN,ZMIN,XMAX,YMAX,ZMAX" when given.
std::optional<Box3d> boxFromArgs(const ArgParser& parser);

/// A real data set of the hull benchmarks, in a data root.
struct HullDataset {
  std::string name, directory, calibration, view_list;  ///< view_list empty: all views
  double threshold;  ///< silhouette threshold; dilation and erosion as SilhouetteConfig
};

/// Dino (the Middlebury recipe, 0.19, and its good-silhouette list) and temple (0.25: a dark
/// cloth behind the object passes 0.19 in several views).
const std::vector<HullDataset>& hullDatasets();

/// The data set's views and silhouettes under `root`.
HullInput loadHullDataset(const std::string& root, const HullDataset& dataset);

/// The object `sift_hull hull --json` prints.
nlohmann::json hullJson(const HullResult& result, size_t occupied_leaves,
                        const ReprojectionIoU& iou);

}  // namespace cli
}  // namespace sift_hull
