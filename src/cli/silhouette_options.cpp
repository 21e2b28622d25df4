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
  parser->addOption("silhouette-method", "NAME",
                    "how silhouettes come from images: background (a colour model of the image "
                    "border, no threshold needed) or threshold (grey above --threshold; the "
                    "default when --threshold is given)",
                    defaults.silhouette_method);
  parser->addOption("threshold", "T", "silhouette threshold on grey intensity in [0, 1]",
                    threshold.str());
  parser->addOption("dilate-px", "PX", "silhouette dilation radius in pixels",
                    std::to_string(defaults.dilate_px));
  parser->addDeprecatedAlias("dilate", {"dilate-px"});
  parser->addOption("erode-px", "PX", "silhouette erosion radius in pixels",
                    std::to_string(defaults.erode_px));
  parser->addDeprecatedAlias("erode", {"erode-px"});
}

SilhouetteConfig silhouetteConfigFromArgs(const ArgParser& parser) {
  SilhouetteConfig config;
  config.silhouette_method = parser.get("silhouette-method");
  // A threshold given asks for the threshold recipe, unless a method is named too.
  if (parser.given("threshold") && !parser.given("silhouette-method")) {
    config.silhouette_method = "threshold";
  }
  config.threshold = parser.getDouble("threshold");
  config.dilate_px = parser.getInt("dilate-px");
  config.erode_px = parser.getInt("erode-px");
  validateOptions(config);
  return config;
}

}  // namespace cli
}  // namespace sift_hull
