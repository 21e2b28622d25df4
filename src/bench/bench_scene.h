#pragma once
// The rendered scene of bench-hull's synthetic and end-to-end cases, and their options for it.

#include <opencv2/core.hpp>
#include <string>
#include <vector>

#include "args.h"
#include "sift_hull/io/calibration.h"
#include "sift_hull/synthetic/shape.h"

namespace sift_hull {
namespace cli {

/// The default sculpture seen by `views` cameras on the sphere layout, each image `size`; with a
/// `support` (SceneConfig::support), the cameras are above it.
struct BenchScene {
  Shape shape;
  std::vector<CalibratedView> cameras;
  cv::Size size;
};
BenchScene benchScene(int views, int width_px, int height_px, const std::string& support = "none");

/// Adds --NAME-views N and --NAME-size WxH with these defaults, `what` naming the case in the help.
void addSceneOptions(ArgParser* parser, const std::string& name, const std::string& what, int views,
                     int width_px, int height_px);

/// Reads them: at least 2 views, each side in [8, 8192]; throws UsageError naming the option.
void sceneFromArgs(const ArgParser& parser, const std::string& name, int* views, int* width_px,
                   int* height_px);

}  // namespace cli
}  // namespace sift_hull
