#include "silhouette_options.h"

#include "setting_options.h"
#include "sift_hull/hull/silhouette.h"

namespace sift_hull {
namespace cli {

void addSilhouetteOptions(ArgParser* parser) {
  parser->addOption("silhouettes", "DIR",
                    "directory of mask files named like the images (default: take them from the "
                    "images by --silhouette-method; --threshold alone chooses the threshold "
                    "method)");
  addSettingOptions(parser, settingsOf<SilhouetteConfig>());
}

SilhouetteConfig silhouetteConfigFromArgs(const ArgParser& parser) {
  SilhouetteConfig config;
  settingsFromArgs(parser, settingsOf<SilhouetteConfig>(), &config);
  // A threshold given asks for the threshold recipe, unless a method is named too.
  if (parser.given("threshold") && !parser.given("silhouette-method")) {
    config.silhouette_method = "threshold";
  }
  validateOptions(config);
  return config;
}

}  // namespace cli
}  // namespace sift_hull
