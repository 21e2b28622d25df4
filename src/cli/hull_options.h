#pragma once

#include <functional>
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

/// --max-input-reduction: the largest reduction (1, 2, 4 or 8) at which `hull` decodes mask
/// files, each view's following from its finest voxel's footprint (loadReducedHullInput), and at
/// which it reads and segments photographs (loadReducedPhotoHullInput).
void addInputReductionOption(ArgParser* parser);
/// Its value; 1 (full resolution) with --refine-with-matches, --photo-carve or --holdout-view,
/// which use the photographs at full resolution.
int maxInputReductionFromArgs(const ArgParser& parser);
/// The views with their masks decoded at the reductions their footprints allow, up to
/// `max_reduction` (loadReducedHullInput; `box` is --box when given); without --silhouettes, the
/// photographs read and segmented at photographReduction() (loadReducedPhotoHullInput, which
/// fills `report`).
HullInput reducedViewSetFromArgs(
    const ArgParser& parser, const HullConfig& config, const std::optional<Box3d>& box,
    int max_reduction, ViewSilhouettes* report = nullptr,
    const std::function<void(size_t read, size_t total)>& on_view_read = {});
/// View `view`'s mask at its image's full size: a reduced mask enlarged (its outline
/// interpolated), else the mask itself.
cv::Mat fullSizeMask(const HullInput& input, size_t view);
/// {"min", "max"} of the views' input reductions, and "image_size" [width, height] of the first.
nlohmann::json inputReductionJson(const HullInput& input);

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
