// hull --refine-with-matches: the filtered matches of calibrated pairs carve what silhouettes
// cannot (src/core/pipeline/match_refinement.cpp); hull --photo-carve: the views' dense depth maps
// carve it (src/core/mvs); and with --gt-scene the result against the renderer's solid.

#include "refine_options.h"

#include <algorithm>
#include <chrono>
#include <memory>
#include <optional>
#include <string>

#include "bench_timing.h"
#include "setting_options.h"
#include "sift_hull/eval/hull_evaluation.h"
#include "sift_hull/filters/filter.h"
#include "sift_hull/io/images.h"
#include "sift_hull/io/ply.h"
#include "sift_hull/io/reduced_images.h"
#include "sift_hull/mvs/mesh_colour.h"
#include "sift_hull/mvs/photo_carving.h"
#include "sift_hull/pipeline/match_refinement.h"
#include "sift_hull/synthetic/scene.h"
#include "sift_hull/synthetic/shape.h"

namespace sift_hull {
namespace cli {
namespace {

/// Samples per axis of the comparison with the true solid (--gt-scene).
constexpr int kSolidSamplesPerAxis = 160;

DenseMatchConfig denseMatchConfigFromArgs(const ArgParser& parser) {
  DenseMatchConfig config;
  config.grid_step_px = parser.getInt("grid-step-px");
  config.patch_radius_px = parser.getInt("patch-radius-px");
  config.min_ncc = parser.getDouble("min-ncc");
  config.min_ncc_margin = parser.getDouble("min-ncc-margin");
  config.min_patch_std = parser.getDouble("min-patch-std");
  config.max_round_trip_px = parser.getDouble("max-round-trip-px");
  validateOptions(config);
  return config;
}

/// How the pairs are chosen and matched (--match-pairs, --filter, --contrast-threshold, --ratio).
void matchSettingsFromArgs(const ArgParser& parser, MatchRefineConfig* config,
                           std::unique_ptr<MatchFilter>* filter) {
  const std::string match_pairs = parser.get("match-pairs");
  if (match_pairs != "neighbours" && match_pairs != "all") {
    throw UsageError("--match-pairs must be neighbours or all, not '" + match_pairs + "'");
  }
  config->pairing = match_pairs == "all" ? ViewPairing::kAll : ViewPairing::kNeighbours;
  try {
    *filter = makeFilter(parser.get("filter"), FilterConfigs());
  } catch (const std::invalid_argument& e) {
    throw UsageError(std::string("--filter: ") + e.what());
  }
  config->pair.sift.contrast_threshold = parser.getDouble("contrast-threshold");
  validateOptions(config->pair.sift);
  config->pair.matching.ratio = parser.getDouble("ratio");
  validateOptions(config->pair.matching);
}

SurfacePointConfig surfacePointConfigFromArgs(const ArgParser& parser) {
  SurfacePointConfig config;
  config.max_reprojection_px = parser.getDouble("max-reprojection-px");
  config.confirm_radius_voxels = parser.getDouble("confirm-radius-voxels");
  validateOptions(config);
  return config;
}

FreeSpaceConfig freeSpaceConfigFromArgs(const ArgParser& parser) {
  FreeSpaceConfig config;
  config.stop_margin_voxels = parser.getDouble("stop-margin-voxels");
  config.min_views = parser.getInt("min-views");
  config.max_edge_fraction = parser.getDouble("max-edge-fraction");
  config.max_slant_deg = parser.getDouble("max-slant-deg");
  config.bulge_fraction = parser.getDouble("bulge-fraction");
  config.keep_radius_voxels = parser.getDouble("keep-radius-voxels");
  validateOptions(config);
  return config;
}

MatchRefineConfig refineConfigFromArgs(const ArgParser& parser,
                                       std::unique_ptr<MatchFilter>* filter) {
  MatchRefineConfig config;
  matchSettingsFromArgs(parser, &config, filter);
  config.dense = denseMatchConfigFromArgs(parser);
  config.points = surfacePointConfigFromArgs(parser);
  config.free_space = freeSpaceConfigFromArgs(parser);
  return config;
}

/// The views as the refinement reads them: --images/<name>, the masks the hull was built from.
RefineViews refineViews(const std::string& folder, const HullInput& input) {
  RefineViews views;
  views.cameras = input.cameras;
  views.image = [folder, &input](uint32_t view) {
    return readImageReduced(folder + "/" + input.names.at(view), input.reduction(view));
  };
  views.mask = [&input](uint32_t view) { return input.mask(view); };
  return views;
}

nlohmann::json solidJson(const SolidComparison& c) {
  return {{"iou", c.iou},
          {"hull_m3", c.hull_m3},
          {"truth_m3", c.truth_m3},
          {"excess_m3", c.excess_m3},
          {"missing_m3", c.missing_m3},
          {"cavity_m3", c.cavity_m3},
          {"cavity_filled_m3", c.cavity_filled_m3}};
}

}  // namespace

PhotoCarveConfig photoConfigFromArgs(const ArgParser& parser) {
  PhotoCarveConfig config;
  settingsFromArgs(parser, settingsOf<PhotoCarveConfig>(), &config);
  return config;
}

void checkRefineOptions(const ArgParser& parser) {
  if (parser.flag("photo-carve")) {
    if (!parser.has("images")) throw UsageError("--photo-carve needs --images");
    static_cast<void>(photoConfigFromArgs(parser));
  }
  if (!parser.flag("refine-with-matches")) return;
  if (!parser.has("images")) throw UsageError("--refine-with-matches needs --images");
  std::unique_ptr<MatchFilter> filter;
  static_cast<void>(refineConfigFromArgs(parser, &filter));
}

void addRefineOptions(ArgParser* parser) {
  const SurfacePointConfig points;
  const FreeSpaceConfig free;
  const DenseMatchConfig dense;
  parser->addFlag("refine-with-matches",
                  "match calibrated pairs of views (SIFT on --images), triangulate the filtered "
                  "matches and carve the lines of sight to them from the hull");
  parser->addOption("match-pairs", "neighbours|all",
                    "pairs to match: each view with its two nearest (camera centres), or all",
                    "neighbours");
  parser->addOption("filter", "NAME", "match filter for --refine-with-matches (makeFilter names)",
                    kDefaultFilter);
  parser->addOption("contrast-threshold", "T",
                    "SIFT's contrast threshold for --refine-with-matches (lower finds more "
                    "features)",
                    numberText(SiftConfig{}.contrast_threshold));
  parser->addOption("ratio", "R",
                    "Lowe's ratio among a keypoint's candidates along its epipolar line "
                    "(--refine-with-matches)",
                    numberText(MatchConfig{}.ratio));
  parser->addOption("grid-step-px", "PX",
                    "dense matching along the epipolar lines: every PX-th pixel of a pair's left "
                    "view searched for in the right one (0: SIFT matches only)",
                    std::to_string(dense.grid_step_px));
  parser->addOption("patch-radius-px", "R", "dense matching compares patches of (2 R + 1)^2 pixels",
                    std::to_string(dense.patch_radius_px));
  parser->addOption("min-ncc", "C", "smallest normalised cross-correlation of a dense match",
                    numberText(dense.min_ncc));
  parser->addOption("min-ncc-margin", "C",
                    "a dense match's correlation must beat every other peak along its epipolar "
                    "line by this much",
                    numberText(dense.min_ncc_margin));
  parser->addOption("min-patch-std", "S",
                    "patches flatter than this (grey level's standard deviation, 0..1) are not "
                    "matched densely",
                    numberText(dense.min_patch_std));
  parser->addOption("max-round-trip-px", "PX",
                    "a dense match searched for back from the right view must end this close to "
                    "its left pixel",
                    numberText(dense.max_round_trip_px));
  parser->addOption("max-reprojection-px", "PX",
                    "largest reprojection error of a surface point in either view",
                    numberText(points.max_reprojection_px));
  parser->addOption(
      "confirm-radius-voxels", "V",
      "points of two pairs sharing a feature confirm each other this close (finest voxels)",
      numberText(points.confirm_radius_voxels));
  parser->addOption("stop-margin-voxels", "V",
                    "a voxel is empty for a view when this many voxels (plus two depth sigmas) in "
                    "front of the surface of its points",
                    numberText(free.stop_margin_voxels));
  parser->addOption("min-views", "N", "views that must see a voxel empty before it is free",
                    std::to_string(free.min_views));
  parser->addOption("max-edge-fraction", "F",
                    "longest triangle of a view's surface of points, as a fraction of the cube's "
                    "edge",
                    numberText(free.max_edge_fraction));
  parser->addOption("max-slant-deg", "DEG",
                    "largest angle between a triangle's normal and the line of sight to it",
                    numberText(free.max_slant_deg));
  parser->addOption("bulge-fraction", "F",
                    "margin added per triangle, as a fraction of its longest edge (the surface "
                    "may bulge towards the camera between points)",
                    numberText(free.bulge_fraction));
  parser->addOption("keep-radius-voxels", "V",
                    "voxels this close to a surface point are never free",
                    numberText(free.keep_radius_voxels));
  parser->addOption("out-points", "PLY",
                    "write the surface points that --refine-with-matches carves with (vertices "
                    "only)");
  parser->addFlag("photo-carve",
                  "carve the hull by the views' dense depth maps (a plane sweep of each view "
                  "against its neighbours within the hull's depth range, on --images), after "
                  "--refine-with-matches when both are given");
  addSettingOptions(parser, settingsOf<PhotoCarveConfig>());
  parser->addOption("gt-scene", "DIR",
                    "a scene `sift_hull scene` rendered: compare the hull with its true solid "
                    "(volume IoU, and with --refine-with-matches or --photo-carve before and "
                    "after, false carving)");
}

namespace {

/// The matches refinement of result->hull (sift_hull::refineWithMatches), carved and meshed
/// again; its part of `hull --json`.
nlohmann::json refine(const ArgParser& parser, const HullInput& input, HullResult* result) {
  std::unique_ptr<MatchFilter> filter;
  const MatchRefineConfig config = refineConfigFromArgs(parser, &filter);
  nlohmann::json json = nlohmann::json::object();
  const ReprojectionIoU iou_before = reprojectionIoU(result->mesh, result->hull.views());
  json["reprojection_iou_before"] = {{"min", iou_before.min}, {"mean", iou_before.mean}};
  const MatchRefineResult refined = sift_hull::refineWithMatches(
      refineViews(parser.get("images"), input), result->hull, *filter, config);
  if (parser.has("out-points")) {
    TriangleMesh cloud;
    for (const SurfacePoint& point : refined.points) {
      cloud.vertices_W.push_back(point.X_W.cast<float>());
    }
    writePly(parser.get("out-points"), cloud);
  }
  const double before_m3 = result->hull.stats().occupied_volume_m3;
  auto start = std::chrono::steady_clock::now();
  result->hull.carveFree(refined.free_voxels);
  const double carve_ms = millisecondsSince(start);
  start = std::chrono::steady_clock::now();
  result->mesh = result->hull.mesh();
  result->mesh_check = checkMesh(result->mesh);
  const SurfacePointCounts& counts = refined.counts;
  json["refine_time_ms"] = {{"matching", refined.times_ms.matching},
                            {"points", refined.times_ms.points},
                            {"free_voxels", refined.times_ms.free_voxels},
                            {"carving", carve_ms},
                            {"mesh", millisecondsSince(start)}};
  json["points"] = {
      {"pairs", refined.view_pairs.size()},     {"matches_kept", refined.sift_matches},
      {"dense_matches", refined.dense_matches}, {"triangulated", counts.triangulated},
      {"reprojected", counts.reprojected},      {"inside_hull", counts.inside_hull},
      {"confirmed", counts.confirmed},          {"kept", counts.kept}};
  json["free_voxels"] = result->hull.freeVoxelCount();
  json["carved_volume_m3"] = before_m3 - result->hull.stats().occupied_volume_m3;
  return json;
}

/// Photo carving of result->hull (sift_hull::photoCarve), carved and meshed again; its part of
/// `hull --json`.
nlohmann::json photoCarve(const ArgParser& parser, const HullInput& input, HullResult* result) {
  const auto start = std::chrono::steady_clock::now();
  const RefineViews refine_views = refineViews(parser.get("images"), input);
  const PhotoViews views{refine_views.cameras, refine_views.image, refine_views.mask};
  const PhotoCarveResult carved =
      sift_hull::photoCarve(result->hull, views, photoConfigFromArgs(parser));
  const size_t free_before = result->hull.freeVoxelCount();
  result->hull.carveFree(carved.free_voxels);
  result->mesh = result->hull.mesh();
  result->mesh_check = checkMesh(result->mesh);
  return {
      {"carved_voxels", result->hull.freeVoxelCount() - free_before},
      {"free_voxels_found", carved.free_voxels.size()},
      {"restored_voxels", carved.restored_voxels},
      {"sweeps", carved.sweeps},
      {"depth_map_scale", {{"min", carved.scale_min}, {"max", carved.scale_max}}},
      {"depth_pixels", {{"swept", carved.depth_pixels}, {"consistent", carved.consistent_pixels}}},
      {"time_ms", millisecondsSince(start)},
      {"stage_ms",
       {{"depth", carved.depth_ms},
        {"consistency", carved.consistency_ms},
        {"voting", carved.voting_ms},
        {"silhouettes", carved.silhouettes_ms}}}};
}

}  // namespace

nlohmann::json refineWithMatches(const ArgParser& parser, const HullInput& input,
                                 HullResult* result) {
  nlohmann::json json = nlohmann::json::object();
  std::optional<Shape> solid;
  if (parser.has("gt-scene")) {
    const SceneData scene = readScene(parser.get("gt-scene"));
    requireViewsOfScene(scene, parser.get("gt-scene"), input, parser.get("calib"));
    solid = Shape::byName(scene.config.shape);
  }
  const SolidPredicate inside = [&](const Eigen::Vector3d& X_W) { return solid->contains(X_W); };
  std::optional<Shape> filled;
  if (solid) filled = solid->withoutCuts();
  const SolidPredicate cavities = [&](const Eigen::Vector3d& X_W) {
    return filled->contains(X_W) && !solid->contains(X_W);
  };
  std::optional<SolidSamples> before;
  if (solid) before = sampleAgainstSolid(result->hull, inside, kSolidSamplesPerAxis, cavities);
  if (parser.flag("refine-with-matches")) json = refine(parser, input, result);
  if (parser.flag("photo-carve")) {
    const double before_m3 = result->hull.stats().occupied_volume_m3;
    json["photo_carving"] = photoCarve(parser, input, result);
    json["photo_carving"]["carved_volume_m3"] = before_m3 - result->hull.stats().occupied_volume_m3;
  }
  if (solid) {
    const SolidSamples after =
        sampleAgainstSolid(result->hull, inside, kSolidSamplesPerAxis, cavities);
    const SolidComparison was = compareWithSolid(*before), is = compareWithSolid(after);
    json["volume_iou_vs_truth"] = {{"before", was.iou}, {"after", is.iou}};
    json["solid"] = {{"before", solidJson(was)}, {"after", solidJson(is)}};
    json["false_carved_fraction"] = falseCarvedFraction(*before, after);
    json["cavity_filled_m3"] = {{"before", was.cavity_filled_m3}, {"after", is.cavity_filled_m3}};
  }
  return json;
}

nlohmann::json colourMesh(const ArgParser& parser, const HullInput& input, HullResult* result) {
  if (!(parser.has("out-mesh") || parser.has("out-color-octree")) || !parser.has("images")) {
    return nlohmann::json::object();
  }
  const auto start = std::chrono::steady_clock::now();
  const RefineViews views = refineViews(parser.get("images"), input);
  const MeshColouring colouring = sift_hull::colourMesh(&result->mesh, views.cameras, views.image,
                                                        result->hull.config().threads);
  return {{"mesh_colours",
           {{"coloured_vertices", colouring.coloured_vertices},
            {"unseen_vertices", colouring.unseen_vertices},
            {"time_ms", millisecondsSince(start)}}}};
}

std::optional<HeldOutView> holdOutView(const ArgParser& parser, HullInput* input) {
  if (!parser.has("holdout-view")) return std::nullopt;
  if (!parser.has("images")) throw UsageError("--holdout-view needs --images");
  const std::string name = parser.get("holdout-view");
  const auto found = std::find(input->names.begin(), input->names.end(), name);
  if (found == input->names.end()) {
    throw UsageError("--holdout-view " + name + " is not one of the views");
  }
  const size_t index = static_cast<size_t>(found - input->names.begin());
  HeldOutView view{name, input->cameras.at(index), input->mask(index)};
  input->names.erase(input->names.begin() + index);
  input->cameras.erase(input->cameras.begin() + index);
  if (input->masks.empty()) {
    input->run_length_masks.erase(input->run_length_masks.begin() + index);
  } else {
    input->masks.erase(input->masks.begin() + index);
  }
  return view;
}

nlohmann::json heldOutError(const ArgParser& parser, const HullInput& input,
                            const HeldOutView& view, TriangleMesh mesh, int threads) {
  // The refined model's mesh is coloured already when --out-mesh asked for it (colourMesh above,
  // by the same views): coloured again only otherwise.
  if (mesh.colours_rgb.size() != mesh.vertices_W.size()) {
    const RefineViews views = refineViews(parser.get("images"), input);
    sift_hull::colourMesh(&mesh, views.cameras, views.image, threads);
  }
  const cv::Mat photo = readImage(parser.get("images") + "/" + view.name);
  const ColourError error =
      colourError(renderColouredMesh(mesh, view.camera, photo.size()), photo, view.mask);
  return {{"mae", error.mae}, {"psnr_db", error.psnr_db}};
}

}  // namespace cli
}  // namespace sift_hull
