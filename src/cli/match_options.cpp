#include "match_options.h"

#include <limits>
#include <sstream>
#include <stdexcept>

#include "sift_hull/filters/filter.h"

namespace sift_hull {
namespace cli {
namespace {

std::string text(double value) {
  std::ostringstream out;
  out << value;
  return out.str();
}

void addSiftOptions(ArgParser* parser) {
  const SiftConfig sift;
  parser->addOption("max-features", "N", "SIFT: keep the N strongest keypoints (0: all)",
                    text(sift.max_features));
  parser->addOption("contrast-threshold", "T", "SIFT contrast threshold",
                    text(sift.contrast_threshold));
  parser->addOption("edge-threshold", "T", "SIFT edge threshold", text(sift.edge_threshold));
  parser->addOption("sigma", "PX", "SIFT base blur in pixels", text(sift.sigma_px));
  parser->addOption("max-image-pixels", "N", "larger images are refused",
                    std::to_string(sift.max_image_pixels));
}

void addMatchingOptions(ArgParser* parser) {
  const MatchConfig matching;
  parser->addOption("ratio", "R", "Lowe's ratio test; 1 turns it off", text(matching.ratio));
  parser->addOption("max-distance", "D",
                    "largest descriptor distance kept (SIFT descriptors have norm 512)", "inf");
  parser->addFlag("cross-check", "keep only mutual nearest neighbours");
  parser->addOption("matcher", "NAME", "brute-force or flann", matching.backend);
}

void addFilterOptions(ArgParser* parser) {
  const FilterConfigs filters;
  parser->addOption("max-epipolar-px", "PX", "epipolar: largest point-to-line distance",
                    text(filters.epipolar.max_epipolar_px));
  parser->addOption("gsc-max-distance", "D", "gsc: largest histogram distance kept",
                    text(filters.gsc.max_histogram_distance));
  parser->addOption("threads", "N", "gsc: threads (0: all)", text(filters.gsc.threads));
  parser->addOption("ransac-px", "PX", "ransac and magsac: inlier threshold",
                    text(filters.ransac.max_epipolar_px));
  parser->addOption("gms-cells", "N", "gms: grid cells per image side",
                    text(filters.gms.grid_cells));
  parser->addFlag("gms-rotation", "gms: try rotated neighbourhoods");
  parser->addFlag("gms-scale", "gms: try scaled right grids");
}

FilterConfigs filterConfigsFromArgs(const ArgParser& parser) {
  FilterConfigs filters;
  filters.epipolar.max_epipolar_px = parser.getDouble("max-epipolar-px");
  filters.gsc.max_histogram_distance = parser.getDouble("gsc-max-distance");
  filters.gsc.threads = parser.getInt("threads");
  filters.ransac.max_epipolar_px = filters.magsac.max_epipolar_px = parser.getDouble("ransac-px");
  filters.gms.grid_cells = parser.getInt("gms-cells");
  filters.gms.with_rotation = parser.flag("gms-rotation");
  filters.gms.with_scale = parser.flag("gms-scale");
  return filters;
}

}  // namespace

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
  options.sift.sigma_px = parser.getDouble("sigma");
  const int max_image_pixels = parser.getInt("max-image-pixels");
  if (max_image_pixels < 1) throw UsageError("--max-image-pixels must be >= 1");
  options.sift.max_image_pixels = static_cast<size_t>(max_image_pixels);
  options.matching.ratio = parser.getDouble("ratio");
  options.matching.max_descriptor_distance = parser.get("max-distance") == "inf"
                                                 ? std::numeric_limits<double>::infinity()
                                                 : parser.getDouble("max-distance");
  options.matching.cross_check = parser.flag("cross-check");
  options.matching.backend = parser.get("matcher");
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
