#include "silhouette_options.h"

#include <sstream>

#include "sift_hull/hull/silhouette.h"

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
  validateOptions(config);
  return config;
}

}  // namespace cli
}  // namespace sift_hull
