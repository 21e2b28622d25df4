#include <opencv2/core.hpp>
#include <sstream>

#include "args.h"
#include "commands.h"
#include "sift_hull/geometry/camera_set.h"
#include "sift_hull/io/calibration.h"
#include "sift_hull/io/images.h"
#include "silhouette_options.h"

namespace sift_hull {
namespace cli {
namespace {

nlohmann::json vectorJson(const Eigen::Vector3d& v) { return {v.x(), v.y(), v.z()}; }

bool projectsInside(const std::vector<CalibratedView>& views, const Eigen::Vector3d& X_W,
                    cv::Size size) {
  for (const CalibratedView& view : views) {
    const Eigen::Vector2d pixel = view.camera.project(X_W);
    if (pixel.x() < -0.5 || pixel.y() < -0.5 || pixel.x() > size.width - 0.5 ||
        pixel.y() > size.height - 0.5) {
      return false;
    }
  }
  return true;
}

nlohmann::json commonPointJson(const std::vector<CalibratedView>& views, cv::Size size) {
  const CommonPoint common = opticalAxesMeetingPoint(camerasOf(views));
  if (!common.well_defined) return {{"looks_at_common_point", false}, {"point", nullptr}};
  const bool inside = projectsInside(views, common.point_W, size);
  return {{"point", vectorJson(common.point_W)},
          {"max_axis_distance_m", common.max_axis_distance_m},
          {"in_front_of_all", common.in_front_of_all},
          {"projects_inside_all", inside},
          {"looks_at_common_point", common.in_front_of_all && inside}};
}

std::string describe(const nlohmann::json& info) {
  std::ostringstream text;
  text << info["views"].get<int>() << " views, images " << info["image_size"][0] << "x"
       << info["image_size"][1] << "\n";
  for (const auto& view : info["cameras"]) {
    text << "  " << view["name"].get<std::string>() << "  centre " << view["centre"].dump()
         << "  silhouette " << 100.0 * view["silhouette_fraction"].get<double>() << " %\n";
  }
  const auto& common = info["common_point"];
  text << "cameras look at a common point: "
       << (common["looks_at_common_point"].get<bool>() ? "yes" : "no");
  if (!common["point"].is_null()) {
    text << " (" << common["point"].dump() << ", farthest optical axis "
         << common["max_axis_distance_m"].get<double>() << " away)";
  }
  text << "\n";
  return text.str();
}

}  // namespace

int runDatasetInfo(const std::vector<std::string>& args) {
  ArgParser parser("dataset-info",
                   "Reads a calibration file and the images it names and reports the number of\n"
                   "views, the image size, the camera centres and whether the cameras look at a\n"
                   "common point (where their optical axes come closest, in front of every camera\n"
                   "and inside every image), and the share of each image its silhouette covers.");
  parser.addOption("calib", "FILE", "Middlebury *_par.txt or a list of 3x4 projection matrices");
  parser.addOption("images", "DIR", "directory of the images (default: the calibration's)");
  addSilhouetteOptions(&parser);
  parser.addFlag("json", "print the result as one JSON object");
  if (!parser.parse(args)) return 0;
  const std::string calib = parser.get("calib");
  const std::string images = parser.has("images") ? parser.get("images") : parentDirectory(calib);

  const std::vector<CalibratedView> views = readCalibration(calib);
  const std::vector<cv::Mat> silhouettes =
      loadSilhouettes(views, images, parser.has("silhouettes") ? parser.get("silhouettes") : "",
                      silhouetteConfigFromArgs(parser));
  const cv::Size size = silhouettes.front().size();  // loadSilhouettes: one size for all
  nlohmann::json cameras = nlohmann::json::array();
  for (size_t i = 0; i < views.size(); ++i) {
    const double fraction = cv::countNonZero(silhouettes[i]) / static_cast<double>(size.area());
    cameras.push_back({{"name", views[i].name},
                       {"centre", vectorJson(views[i].camera.centre())},
                       {"silhouette_fraction", fraction}});
  }
  const nlohmann::json info = {{"calib", calib},
                               {"views", views.size()},
                               {"image_size", {size.width, size.height}},
                               {"cameras", cameras},
                               {"common_point", commonPointJson(views, size)}};
  printResult(parser.flag("json"), info, describe(info));
  return 0;
}

}  // namespace cli
}  // namespace sift_hull
