#include "silhouette_options.h"

#include <sstream>

namespace sift_hull {
namespace cli {

void addSilhouetteOptions(ArgParser* parser) {
  const SilhouetteConfig defaults;
  std::ostringstream threshold;
  threshold << defaults.threshold;
  parser->addOption("silhouettes", "DIR",
                    "directory of mask files named like the images (default: extract them from "
                    "the images)");
  parser->addOption("threshold", "T", "silhouette threshold on grey intensity in [0, 1]",
                    threshold.str());
  parser->addOption("dilate", "PX", "silhouette dilation radius in pixels",
                    std::to_string(defaults.dilate_px));
  parser->addOption("erode", "PX", "silhouette erosion radius in pixels",
                    std::to_string(defaults.erode_px));
}

SilhouetteConfig silhouetteConfigFromArgs(const ArgParser& parser) {
  SilhouetteConfig config;
  config.threshold = parser.getDouble("threshold");
  config.dilate_px = parser.getInt("dilate");
  config.erode_px = parser.getInt("erode");
  if (config.threshold < 0.0 || config.threshold > 1.0) {
    throw UsageError("--threshold must lie in [0, 1]");
  }
  if (config.dilate_px < 0 || config.erode_px < 0) {
    throw UsageError("--dilate and --erode must not be negative");
  }
  return config;
}

}  // namespace cli
}  // namespace sift_hull
