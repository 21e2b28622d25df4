#include "match_options.h"

#include <limits>
#include <sstream>
#include <stdexcept>

#include "sift_hull/filters/filter.h"

namespace sift_hull {
namespace cli {
namespace {

void addSiftOptions(ArgParser* parser) {
  const SiftConfig sift;
  parser->addOption("max-features", "N", "SIFT: keep the N strongest keypoints (0: all)",
                    numberText(sift.max_features));
  parser->addOption("contrast-threshold", "T", "SIFT contrast threshold",
                    numberText(sift.contrast_threshold));
  parser->addOption("edge-threshold", "T", "SIFT edge threshold", numberText(sift.edge_threshold));
  parser->addOption("sigma-px", "PX", "SIFT base blur in pixels", numberText(sift.sigma_px));
  parser->addDeprecatedAlias("sigma", {"sigma-px"});
  parser->addOption("max-image-pixels", "N", "larger images are refused",
                    std::to_string(sift.max_image_pixels));
}

void addMatchingOptions(ArgParser* parser) {
  const MatchConfig matching;
  parser->addOption("ratio", "R", "Lowe's ratio test; 1 turns it off", numberText(matching.ratio));
  parser->addOption("max-descriptor-distance", "D",
                    "largest descriptor distance kept (SIFT descriptors have norm 512)", "inf");
  parser->addDeprecatedAlias("max-distance", {"max-descriptor-distance"});
  parser->addFlag("cross-check", "keep only mutual nearest neighbours");
  parser->addOption("backend", "NAME",
                    "blas (exact, default), brute-force (OpenCV, exact) or flann",
                    matching.backend);
  parser->addDeprecatedAlias("matcher", {"backend"});
}

void addLocalFilterOptions(ArgParser* parser, const FilterConfigs& filters) {
  parser->addOption("lsc-neighbours", "K", "lsc: nearest matches looked at in each image",
                    numberText(filters.lsc.lsc_neighbours));
  parser->addOption("lsc-max-relative-error", "E",
                    "lsc: tolerance as a share of the neighbour's distance",
                    numberText(filters.lsc.lsc_max_relative_error));
  parser->addOption("lsc-min-tolerance-px", "PX", "lsc: tolerance floor",
                    numberText(filters.lsc.lsc_min_tolerance_px));
  parser->addOption("lsc-min-support", "S", "lsc: share of neighbours that must agree",
                    numberText(filters.lsc.lsc_min_support));
  parser->addOption("local-gsc-neighbours", "K", "local_gsc: nearest matches in each image",
                    numberText(filters.local_gsc.local_gsc_neighbours));
  parser->addOption("local-gsc-max-histogram-distance", "D",
                    "local_gsc: largest histogram distance kept",
                    numberText(filters.local_gsc.local_gsc_max_histogram_distance));
  const GuidedConfig& guided = filters.guided;
  parser->addOption("guided-max-transfer-px", "PX", "guided: homography inlier threshold",
                    numberText(guided.guided_max_transfer_px));
  parser->addOption("guided-homography-share", "S",
                    "guided: use H when it explains this share of F's inliers",
                    numberText(guided.guided_homography_share));
  parser->addOption("guided-max-models", "N", "guided: motions looked for",
                    numberText(guided.guided_max_models));
  parser->addOption("guided-min-model-inliers", "N", "guided: inliers a motion needs",
                    numberText(guided.guided_min_model_inliers));
  parser->addOption("guided-min-support", "S", "guided: lsc support a match needs",
                    numberText(guided.guided_min_support));
  parser->addOption("guided-max-fit-points", "N", "guided: lsc survivors MAGSAC fits to (sample)",
                    numberText(guided.guided_max_fit_points));
  const VoteRansacConfig& vote = filters.vote_ransac;
  parser->addOption("vote-ransac-max-angle-deg", "DEG",
                    "vote_ransac: half width of the rotation vote",
                    numberText(vote.vote_ransac_max_angle_deg));
  parser->addOption("vote-ransac-max-scale-ratio", "S",
                    "vote_ransac: half width of the scale vote (factor)",
                    numberText(vote.vote_ransac_max_scale_ratio));
  parser->addOption("vote-ransac-max-fit-points", "N", "vote_ransac: putatives fitted (sample)",
                    numberText(vote.vote_ransac_max_fit_points));
}

void localFilterConfigsFromArgs(const ArgParser& parser, FilterConfigs* filters) {
  filters->lsc.lsc_neighbours = parser.getInt("lsc-neighbours");
  filters->lsc.lsc_max_relative_error = parser.getDouble("lsc-max-relative-error");
  filters->lsc.lsc_min_tolerance_px = parser.getDouble("lsc-min-tolerance-px");
  filters->lsc.lsc_min_support = parser.getDouble("lsc-min-support");
  filters->local_gsc.local_gsc_neighbours = parser.getInt("local-gsc-neighbours");
  filters->local_gsc.local_gsc_max_histogram_distance =
      parser.getDouble("local-gsc-max-histogram-distance");
  GuidedConfig& guided = filters->guided;
  guided.guided_max_transfer_px = parser.getDouble("guided-max-transfer-px");
  guided.guided_homography_share = parser.getDouble("guided-homography-share");
  guided.guided_max_models = parser.getInt("guided-max-models");
  guided.guided_min_model_inliers = parser.getInt("guided-min-model-inliers");
  guided.guided_min_support = parser.getDouble("guided-min-support");
  guided.guided_max_fit_points = parser.getInt("guided-max-fit-points");
  VoteRansacConfig& vote = filters->vote_ransac;
  vote.vote_ransac_max_angle_deg = parser.getDouble("vote-ransac-max-angle-deg");
  vote.vote_ransac_max_scale_ratio = parser.getDouble("vote-ransac-max-scale-ratio");
  vote.vote_ransac_max_fit_points = parser.getInt("vote-ransac-max-fit-points");
}

}  // namespace

void addFilterOptions(ArgParser* parser) {
  const FilterConfigs filters;
  parser->addOption("max-epipolar-px", "PX", "epipolar: largest point-to-line distance",
                    numberText(filters.epipolar.max_epipolar_px));
  parser->addOption("max-histogram-distance", "D", "gsc: largest histogram distance kept",
                    numberText(filters.gsc.max_histogram_distance));
  parser->addDeprecatedAlias("gsc-max-distance", {"max-histogram-distance"});
  parser->addOption("threads", "N", "gsc: threads (0: all)", numberText(filters.gsc.threads));
  parser->addOption("max-support", "M", "gsc: histograms over M sampled matches (0: all, exact)",
                    numberText(filters.gsc.max_support));
  parser->addOption("ransac-max-epipolar-px", "PX", "ransac: inlier threshold",
                    numberText(filters.ransac.max_epipolar_px));
  parser->addOption("magsac-max-epipolar-px", "PX", "magsac: inlier threshold",
                    numberText(filters.magsac.max_epipolar_px));
  parser->addDeprecatedAlias("ransac-px", {"ransac-max-epipolar-px", "magsac-max-epipolar-px"});
  parser->addOption("grid-cells", "N", "gms: grid cells per image side",
                    numberText(filters.gms.grid_cells));
  parser->addDeprecatedAlias("gms-cells", {"grid-cells"});
  parser->addOption("threshold-factor", "A", "gms: alpha in the cell-pair threshold alpha sqrt(n)",
                    numberText(filters.gms.threshold_factor));
  parser->addFlag("with-rotation", "gms: try rotated neighbourhoods");
  parser->addDeprecatedAlias("gms-rotation", {"with-rotation"});
  parser->addFlag("with-scale", "gms: try scaled right grids");
  parser->addDeprecatedAlias("gms-scale", {"with-scale"});
  parser->addOption("ransac-seed", "N", "ransac: random state", numberText(filters.ransac.seed));
  parser->addOption("magsac-seed", "N", "magsac (and guided, vote_ransac, best): random state",
                    numberText(filters.magsac.seed));
  addLocalFilterOptions(parser, filters);
}

FilterConfigs filterConfigsFromArgs(const ArgParser& parser) {
  FilterConfigs filters;
  filters.epipolar.max_epipolar_px = parser.getDouble("max-epipolar-px");
  filters.gsc.max_histogram_distance = parser.getDouble("max-histogram-distance");
  filters.gsc.threads = parser.getInt("threads");
  filters.gsc.max_support = parser.getInt("max-support");
  filters.ransac.max_epipolar_px = parser.getDouble("ransac-max-epipolar-px");
  filters.magsac.max_epipolar_px = parser.getDouble("magsac-max-epipolar-px");
  filters.gms.grid_cells = parser.getInt("grid-cells");
  filters.gms.threshold_factor = parser.getDouble("threshold-factor");
  filters.gms.with_rotation = parser.flag("with-rotation");
  filters.gms.with_scale = parser.flag("with-scale");
  filters.ransac.seed = parser.getInt("ransac-seed");
  filters.magsac.seed = parser.getInt("magsac-seed");
  localFilterConfigsFromArgs(parser, &filters);
  try {
    validate(filters);
  } catch (const std::invalid_argument& error) {
    throw UsageError(error.what());
  }
  return filters;
}

void addMatchOptions(ArgParser* parser) {
  addSiftOptions(parser);
  addMatchingOptions(parser);
  addFilterOptions(parser);
}

MatchOptions matchOptionsFromArgs(const ArgParser& parser) {
  MatchOptions options;
  options.sift.max_features = parser.getInt("max-features");
  options.sift.contrast_threshold = parser.getDouble("contrast-threshold");
  options.sift.edge_threshold = parser.getDouble("edge-threshold");
  options.sift.sigma_px = parser.getDouble("sigma-px");
  const int max_image_pixels = parser.getInt("max-image-pixels");
  if (max_image_pixels < 1) throw UsageError("--max-image-pixels must be >= 1");
  options.sift.max_image_pixels = static_cast<size_t>(max_image_pixels);
  options.matching.ratio = parser.getDouble("ratio");
  options.matching.max_descriptor_distance = parser.get("max-descriptor-distance") == "inf"
                                                 ? std::numeric_limits<double>::infinity()
                                                 : parser.getDouble("max-descriptor-distance");
  options.matching.cross_check = parser.flag("cross-check");
  options.matching.backend = parser.get("backend");
  options.filters = filterConfigsFromArgs(parser);
  try {
    validate(options.sift);
    validate(options.matching);
    validate(options.filters);
  } catch (const std::invalid_argument& error) {
    throw UsageError(error.what());
  }
  return options;
}

}  // namespace cli
}  // namespace sift_hull
