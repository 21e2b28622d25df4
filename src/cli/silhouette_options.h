#pragma once

#include <functional>
#include <nlohmann/json.hpp>

#include "args.h"
#include "sift_hull/hull/silhouette.h"
#include "sift_hull/hull/view_silhouettes.h"
#include "sift_hull/io/calibration.h"

namespace sift_hull {
namespace cli {

/// --silhouettes DIR, or --threshold / --dilate-px / --erode-px for the Middlebury recipe, with
/// the defaults of SilhouetteConfig.
void addSilhouetteOptions(ArgParser* parser);
SilhouetteConfig silhouetteConfigFromArgs(const ArgParser& parser);

/// --out-silhouettes DIR: write the silhouettes used.
void addSilhouetteOutputOption(ArgParser* parser);
/// With --out-silhouettes, writes each view's mask (`mask(i)`, CV_8UC1) as DIR/NAME, the image's
/// name with the extension .png (sub-directories created).
void writeSilhouettesFromArgs(const ArgParser& parser, const std::vector<std::string>& names,
                              const std::function<cv::Mat(size_t)>& mask);
/// With --out-silhouettes and the views method, also its priors and coarse hull projections at
/// the working size: DIR/prior/NAME.png and DIR/hull_projection/NAME.png.
void writeViewPriorsFromArgs(const ArgParser& parser, const std::vector<std::string>& names,
                             const ViewSilhouettes& found);
/// What the "views" method found, for the JSON: the ball, the support cut, time, warnings.
nlohmann::json viewSilhouettesJson(const ViewSilhouettes& report);

}  // namespace cli
}  // namespace sift_hull
