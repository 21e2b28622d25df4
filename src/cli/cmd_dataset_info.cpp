#include <algorithm>
#include <iomanip>
#include <opencv2/core.hpp>
#include <optional>
#include <sstream>

#include "args.h"
#include "commands.h"
#include "sift_hull/geometry/camera_set.h"
#include "sift_hull/io/calibration.h"
#include "sift_hull/io/idr.h"
#include "sift_hull/io/images.h"
#include "silhouette_options.h"

namespace sift_hull {
namespace cli {
namespace {

nlohmann::json vectorJson(const Eigen::Vector3d& v) { return {v.x(), v.y(), v.z()}; }

/// Index of the first view the point projects outside of (or -1).
int firstOutside(const std::vector<CalibratedView>& views, const Eigen::Vector3d& X_W,
                 cv::Size size) {
  for (size_t i = 0; i < views.size(); ++i) {
    const Eigen::Vector2d pixel = views[i].camera.project(X_W);
    if (!(pixel.x() >= -0.5 && pixel.y() >= -0.5 && pixel.x() <= size.width - 0.5 &&
          pixel.y() <= size.height - 0.5)) {
      return static_cast<int>(i);
    }
  }
  return -1;
}

nlohmann::json commonPointJson(const std::vector<CalibratedView>& views, cv::Size size) {
  const CommonPoint common = opticalAxesMeetingPoint(camerasOf(views));
  if (!common.well_defined) {
    const std::string reason =
        views.size() < 2 ? "fewer than two views" : "the optical axes are (nearly) parallel";
    return {{"looks_at_common_point", false}, {"point", nullptr}, {"reason", reason}};
  }
  const int outside = firstOutside(views, common.point_W, size);
  std::string reason;
  if (common.first_behind >= 0) {
    reason = "the point is behind camera " + views[common.first_behind].name;
  } else if (outside >= 0) {
    reason = "the point projects outside the image of " + views[outside].name;
  }
  nlohmann::json result = {{"point", vectorJson(common.point_W)},
                           {"max_axis_distance_m", common.max_axis_distance_m},
                           {"in_front_of_all", common.in_front_of_all},
                           {"projects_inside_all", outside < 0},
                           {"looks_at_common_point", common.in_front_of_all && outside < 0}};
  result["reason"] = reason.empty() ? nlohmann::json(nullptr) : nlohmann::json(reason);
  return result;
}

/// The box around IDR's object sphere (idrObjectBox), or null without a scale_mat_0.
nlohmann::json idrBoxJson(const std::string& calib) {
  const std::optional<Box3d> box = idrObjectBox(calib);
  if (!box) return nullptr;
  std::ostringstream option;
  option << std::setprecision(9);
  for (int i = 0; i < 6; ++i) {
    option << (i ? "," : "") << (i < 3 ? box->min_W(i) : box->max_W(i - 3));
  }
  return {{"min", vectorJson(box->min_W)},
          {"max", vectorJson(box->max_W)},
          {"box_option", option.str()}};
}

nlohmann::json distortionJson(const LensDistortion& d) {
  return {{"k1", d.k1}, {"k2", d.k2}, {"p1", d.p1}, {"p2", d.p2},
          {"k3", d.k3}, {"k4", d.k4}, {"k5", d.k5}, {"k6", d.k6}};
}

/// "PINHOLE, no distortion" for each distinct model and distortion, joined by "; ".
std::string describeModels(const std::vector<CalibratedView>& views) {
  std::vector<std::string> seen;
  for (const CalibratedView& view : views) {
    const std::string text = "camera model " +
                             (view.camera_model.empty() ? "unknown" : view.camera_model) + ", " +
                             describeDistortion(view.camera.distortion());
    if (std::find(seen.begin(), seen.end(), text) == seen.end()) seen.push_back(text);
  }
  std::string joined;
  for (size_t i = 0; i < seen.size() && i < 4; ++i) joined += (i ? "; " : "") + seen[i];
  if (seen.size() > 4) joined += "; ... (" + std::to_string(seen.size()) + " different)";
  return joined;
}

std::string describe(const nlohmann::json& info) {
  std::ostringstream text;
  text << "format: " << info["format"].get<std::string>() << ", "
       << info["camera_models"].get<std::string>() << "\n";
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
  if (!common["reason"].is_null()) text << ": " << common["reason"].get<std::string>();
  text << "\n";
  if (info.contains("idr_object_box") && !info["idr_object_box"].is_null()) {
    const auto& box = info["idr_object_box"];
    text << "IDR object box (scale_mat_0's unit sphere): " << box["min"].dump() << " .. "
         << box["max"].dump() << " (--box " << box["box_option"].get<std::string>() << ")\n";
  }
  return text.str();
}

}  // namespace

int runDatasetInfo(const std::vector<std::string>& args) {
  ArgParser parser("dataset-info",
                   "Reads a calibration file and the images it names and reports the number of\n"
                   "views, the image size, the camera centres and whether the cameras look at a\n"
                   "common point (where their optical axes come closest, in front of every camera\n"
                   "and inside every image), and the share of each image its silhouette covers.");
  parser.addOption("calib", "FILE|DIR",
                   "Middlebury *_par.txt, a list of 3x4 projection matrices, a COLMAP sparse model "
                   "directory, an LLFF poses_bounds.npy, a NeRF transforms.json or an IDR / NeuS "
                   "cameras.npz (or the directory holding it)");
  parser.addOption(
      "images", "DIR",
      "directory of the images (default: the calibration file's, the COLMAP model directory, "
      "or IDR's image/ beside cameras.npz)");
  addSilhouetteOptions(&parser);
  addSilhouetteOutputOption(&parser);
  parser.addFlag("json", "print the result as one JSON object");
  if (!parser.parse(args)) return 0;
  const std::string calib = parser.get("calib");
  const std::string format = calibrationFormat(calib);
  // A COLMAP model is a directory: its images default to that directory, IDR's to its image/, a
  // file's to its own.
  const bool idr = format == "IDR cameras.npz";
  const std::string images = parser.has("images")             ? parser.get("images")
                             : format.rfind("COLMAP", 0) == 0 ? calib
                             : idr ? idrImageDirectory(idrCamerasFile(calib), "")
                                   : parentDirectory(calib);

  const std::vector<CalibratedView> views = readCalibrationWithImages(calib, images);
  ViewSilhouettes found;
  const std::vector<cv::Mat> silhouettes =
      loadSilhouettes(views, images, parser.has("silhouettes") ? parser.get("silhouettes") : "",
                      silhouetteConfigFromArgs(parser), &found);
  std::vector<std::string> names;
  for (const CalibratedView& view : views) names.push_back(view.name);
  writeSilhouettesFromArgs(parser, names, [&](size_t i) { return silhouettes[i]; });
  writeViewPriorsFromArgs(parser, names, found);
  const cv::Size size = silhouettes.front().size();  // loadSilhouettes: one size for all
  nlohmann::json cameras = nlohmann::json::array();
  for (size_t i = 0; i < views.size(); ++i) {
    const double fraction = cv::countNonZero(silhouettes[i]) / static_cast<double>(size.area());
    cameras.push_back({{"name", views[i].name},
                       {"centre", vectorJson(views[i].camera.centre())},
                       {"silhouette_fraction", fraction},
                       {"camera_model", views[i].camera_model},
                       {"distortion", distortionJson(views[i].camera.distortion())}});
  }
  nlohmann::json info = {{"calib", calib},
                         {"format", format},
                         {"camera_models", describeModels(views)},
                         {"views", views.size()},
                         {"image_size", {size.width, size.height}},
                         {"cameras", cameras},
                         {"common_point", commonPointJson(views, size)}};
  if (found.ball_centre_W || !found.background_reason.empty()) {
    info["silhouettes"] = viewSilhouettesJson(found);
  }
  if (idr) info["idr_object_box"] = idrBoxJson(calib);
  printResult(parser.flag("json"), info, describe(info));
  return 0;
}

}  // namespace cli
}  // namespace sift_hull
