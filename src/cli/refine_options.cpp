// hull --refine-with-matches: the filtered matches of calibrated pairs carve what silhouettes
// cannot (src/core/refine), and with --gt-scene the result against the renderer's solid.

#include "refine_options.h"

#include <algorithm>
#include <chrono>
#include <iostream>
#include <memory>
#include <optional>
#include <set>
#include <sstream>

#include "bench_timing.h"
#include "sift_hull/eval/hull_evaluation.h"
#include "sift_hull/features/sift.h"
#include "sift_hull/filters/filter.h"
#include "sift_hull/io/images.h"
#include "sift_hull/io/ply.h"
#include "sift_hull/refine/dense_matching.h"
#include "sift_hull/refine/free_space.h"
#include "sift_hull/refine/surface_points.h"
#include "sift_hull/synthetic/scene.h"
#include "sift_hull/synthetic/shape.h"

namespace sift_hull {
namespace cli {
namespace {

/// Samples per axis of the comparison with the true solid (--gt-scene).
constexpr int kSolidSamplesPerAxis = 160;
/// SIFT's contrast threshold for refinement: lower than SiftConfig's 0.04, for denser points.
constexpr double kRefineContrastThreshold = 0.04;
/// How far from its epipolar line a match may lie in guided matching, pixels.
constexpr double kGuidedEpipolarPx = 2.0;
/// Views each view pairs with under --match-pairs neighbours: its nearest by camera centre.
constexpr size_t kNeighbours = 2;

/// (a, b) with a < b: each view with its kNeighbours nearest, or every pair.
std::vector<std::pair<uint32_t, uint32_t>> viewPairs(const std::vector<PinholeCamera>& cameras,
                                                     bool all) {
  std::set<std::pair<uint32_t, uint32_t>> pairs;
  const uint32_t n = static_cast<uint32_t>(cameras.size());
  for (uint32_t a = 0; a < n; ++a) {
    std::vector<uint32_t> others;
    for (uint32_t b = 0; b < n; ++b) {
      if (b != a) others.push_back(b);
    }
    const Eigen::Vector3d centre = cameras[a].centre();
    std::sort(others.begin(), others.end(), [&](uint32_t x, uint32_t y) {
      return (cameras[x].centre() - centre).norm() < (cameras[y].centre() - centre).norm();
    });
    if (!all && others.size() > kNeighbours) others.resize(kNeighbours);
    for (const uint32_t b : others) pairs.insert({std::min(a, b), std::max(a, b)});
  }
  return {pairs.begin(), pairs.end()};
}

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

/// Each view's image, SIFT features and dense-matching image, read once when first needed.
class ViewImages {
 public:
  ViewImages(std::string folder, const HullInput& input, SiftConfig sift, int patch_radius_px)
      : folder_(std::move(folder)),
        input_(input),
        sift_(sift),
        patch_radius_px_(patch_radius_px),
        views_(input.names.size()) {}

  const Features& features(uint32_t view) {
    View& v = load(view);
    if (!v.features) v.features = detectSift(v.image, sift_);
    return *v.features;
  }
  const DenseView& dense(uint32_t view) {
    View& v = load(view);
    if (v.dense.grey.empty()) {
      const cv::Mat mask =
          input_.masks.empty() ? input_.run_length_masks.at(view).decode() : input_.masks.at(view);
      v.dense = denseMatchingView(v.image, mask, patch_radius_px_);
    }
    return v.dense;
  }
  cv::Size size(uint32_t view) { return load(view).image.size(); }

 private:
  struct View {
    cv::Mat image;
    DenseView dense;
    std::optional<Features> features;
  };
  View& load(uint32_t view) {
    View& v = views_.at(view);
    if (v.image.empty()) v.image = readImage(folder_ + "/" + input_.names[view]);
    return v;
  }
  std::string folder_;
  const HullInput& input_;
  SiftConfig sift_;
  int patch_radius_px_;
  std::vector<View> views_;
};

/// The SIFT matches of a pair that its filter keeps, with their keypoint ids.
PairMatches keptSiftMatches(ViewImages* images, const HullInput& input, uint32_t a, uint32_t b,
                            const MatchConfig& matching, const MatchFilter& filter) {
  const Features& left = images->features(a);
  const Features& right = images->features(b);
  PutativeMatches putative;
  putative.matches = matchAlongEpipolarLines(left, right, input.cameras[a], input.cameras[b],
                                             matching, kGuidedEpipolarPx);
  putative.left_keypoints = left.keypoints;
  putative.right_keypoints = right.keypoints;
  putative.left_image_size = images->size(a);
  putative.right_image_size = images->size(b);
  calibratePair(&putative, input.cameras[a], input.cameras[b]);
  const FilterResult kept = filter.apply(putative);
  PairMatches pair;
  pair.left_view = a, pair.right_view = b;
  for (size_t m = 0; m < putative.matches.size(); ++m) {
    if (!kept.keep[m]) continue;
    pair.left_px.emplace_back(putative.left(m).pt.x, putative.left(m).pt.y);
    pair.right_px.emplace_back(putative.right(m).pt.x, putative.right(m).pt.y);
    pair.left_keypoint.push_back(putative.matches[m].queryIdx);
    pair.right_keypoint.push_back(putative.matches[m].trainIdx);
  }
  return pair;
}

/// What matching the pairs found: each pair's kept SIFT matches (with keypoint ids), then each
/// pair's dense matches (DenseMatchConfig, none when its grid_step_px is 0).
struct MatchedPairs {
  std::vector<PairMatches> pairs;
  size_t view_pairs = 0, sift_matches = 0, dense_matches = 0;
};

/// How the pairs are chosen and matched (--match-pairs, --filter, --contrast-threshold, --ratio).
struct MatchSettings {
  bool all_pairs = false;
  std::unique_ptr<MatchFilter> filter;
  SiftConfig sift;
  MatchConfig matching;
};

MatchSettings matchSettingsFromArgs(const ArgParser& parser) {
  MatchSettings settings;
  const std::string match_pairs = parser.get("match-pairs");
  if (match_pairs != "neighbours" && match_pairs != "all") {
    throw UsageError("--match-pairs must be neighbours or all, not '" + match_pairs + "'");
  }
  settings.all_pairs = match_pairs == "all";
  const FilterConfigs filter_configs;
  try {
    settings.filter = makeFilter(parser.get("filter"), filter_configs);
  } catch (const std::invalid_argument& e) {
    throw UsageError(std::string("--filter: ") + e.what());
  }
  settings.sift.contrast_threshold = parser.getDouble("contrast-threshold");
  validateOptions(settings.sift);
  settings.matching.ratio = parser.getDouble("ratio");
  validateOptions(settings.matching);
  return settings;
}

MatchedPairs matchedPairs(const ArgParser& parser, const HullInput& input, const VisualHull& hull) {
  if (!parser.has("images")) throw UsageError("--refine-with-matches needs --images");
  const MatchSettings settings = matchSettingsFromArgs(parser);
  const DenseMatchConfig dense = denseMatchConfigFromArgs(parser);
  ViewImages images(parser.get("images"), input, settings.sift, dense.patch_radius_px);
  const auto view_pairs = viewPairs(input.cameras, settings.all_pairs);
  MatchedPairs result;
  result.view_pairs = view_pairs.size();
  for (const auto& [a, b] : view_pairs) {
    result.pairs.push_back(
        keptSiftMatches(&images, input, a, b, settings.matching, *settings.filter));
    result.sift_matches += result.pairs.back().left_px.size();
  }
  if (dense.grid_step_px == 0) return result;
  for (const auto& [a, b] : view_pairs) {
    result.pairs.push_back(denseMatches(images.dense(a), images.dense(b), input.cameras[a],
                                        input.cameras[b], a, b, hull, dense,
                                        hull.config().threads));
    result.dense_matches += result.pairs.back().left_px.size();
  }
  return result;
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

void checkRefineOptions(const ArgParser& parser) {
  if (!parser.flag("refine-with-matches")) return;
  if (!parser.has("images")) throw UsageError("--refine-with-matches needs --images");
  static_cast<void>(matchSettingsFromArgs(parser));
  static_cast<void>(denseMatchConfigFromArgs(parser));
  static_cast<void>(surfacePointConfigFromArgs(parser));
  static_cast<void>(freeSpaceConfigFromArgs(parser));
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
                    "SIFT's contrast threshold for --refine-with-matches (SiftConfig's default: "
                    "0.04; lower finds more features)",
                    numberText(kRefineContrastThreshold));
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
  parser->addOption("gt-scene", "DIR",
                    "a scene `sift_hull scene` rendered: compare the hull with its true solid "
                    "(volume IoU, and with --refine-with-matches before and after, false carving)");
}

nlohmann::json refineWithMatches(const ArgParser& parser, const HullInput& input,
                                 HullResult* result) {
  nlohmann::json json = nlohmann::json::object();
  const bool refine = parser.flag("refine-with-matches");
  std::optional<Shape> solid;
  if (parser.has("gt-scene")) solid = Shape::byName(readScene(parser.get("gt-scene")).config.shape);
  const SolidPredicate inside = [&](const Eigen::Vector3d& X_W) { return solid->contains(X_W); };
  std::optional<Shape> filled;
  if (solid) filled = solid->withoutCuts();
  const SolidPredicate cavities = [&](const Eigen::Vector3d& X_W) {
    return filled->contains(X_W) && !solid->contains(X_W);
  };
  std::optional<SolidSamples> before;
  if (solid) before = sampleAgainstSolid(result->hull, inside, kSolidSamplesPerAxis, cavities);
  if (refine) {
    const SurfacePointConfig point_config = surfacePointConfigFromArgs(parser);
    const FreeSpaceConfig free_config = freeSpaceConfigFromArgs(parser);
    const ReprojectionIoU iou_before = reprojectionIoU(result->mesh, result->hull.views());
    json["reprojection_iou_before"] = {{"min", iou_before.min}, {"mean", iou_before.mean}};
    auto start = std::chrono::steady_clock::now();
    const auto lapMs = [&start] {
      const double ms = millisecondsSince(start);
      start = std::chrono::steady_clock::now();
      return ms;
    };
    const MatchedPairs matched = matchedPairs(parser, input, result->hull);
    const std::vector<PairMatches>& pairs = matched.pairs;
    const double matching_ms = lapMs();
    SurfacePointCounts counts;
    const std::vector<SurfacePoint> points =
        surfacePoints(input.cameras, pairs, result->hull, point_config, &counts);
    const double points_ms = lapMs();
    if (parser.has("out-points")) {
      TriangleMesh cloud;
      for (const SurfacePoint& point : points) cloud.vertices_W.push_back(point.X_W.cast<float>());
      writePly(parser.get("out-points"), cloud);
    }
    const double before_m3 = result->hull.stats().occupied_volume_m3;
    const std::vector<Eigen::Vector3i> free =
        freeVoxels(result->hull, input.cameras, points, free_config);
    const double free_ms = lapMs();
    result->hull.carveFree(free);
    const double carve_ms = lapMs();
    result->mesh = result->hull.mesh();
    result->mesh_check = checkMesh(result->mesh);
    json["refine_time_ms"] = {{"matching", matching_ms},
                              {"points", points_ms},
                              {"free_voxels", free_ms},
                              {"carving", carve_ms},
                              {"mesh", lapMs()}};
    json["points"] = {{"pairs", matched.view_pairs},
                      {"matches_kept", matched.sift_matches},
                      {"dense_matches", matched.dense_matches},
                      {"triangulated", counts.triangulated},
                      {"reprojected", counts.reprojected},
                      {"inside_hull", counts.inside_hull},
                      {"confirmed", counts.confirmed},
                      {"kept", counts.kept}};
    json["free_voxels"] = result->hull.freeVoxelCount();
    json["carved_volume_m3"] = before_m3 - result->hull.stats().occupied_volume_m3;
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

}  // namespace cli
}  // namespace sift_hull
