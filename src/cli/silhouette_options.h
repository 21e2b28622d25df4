#pragma once

#include "args.h"
#include "sift_hull/hull/silhouette.h"
#include "sift_hull/io/calibration.h"

namespace sift_hull {
namespace cli {

/// --silhouettes DIR, or --threshold / --dilate-px / --erode-px for the Middlebury recipe, with
/// the defaults of SilhouetteConfig.
void addSilhouetteOptions(ArgParser* parser);
SilhouetteConfig silhouetteConfigFromArgs(const ArgParser& parser);

}  // namespace cli
}  // namespace sift_hull
