#include "silhouette_options.h"

#include <filesystem>
#include <opencv2/imgcodecs.hpp>
#include <stdexcept>

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

void addSilhouetteOutputOption(ArgParser* parser) {
  parser->addOption("out-silhouettes", "DIR",
                    "write the silhouettes used, one PNG per view named like its image (.png), to "
                    "look at and correct; --silhouettes DIR reads them back");
}

namespace {

void writeMasks(const std::string& directory, const std::vector<std::string>& names,
                const std::function<cv::Mat(size_t)>& mask) {
  for (size_t i = 0; i < names.size(); ++i) {
    std::string name = names[i];
    const std::string::size_type dot = name.find_last_of('.'), slash = name.find_last_of('/');
    if (dot != std::string::npos && (slash == std::string::npos || dot > slash)) name.erase(dot);
    const std::string path = directory + "/" + name + ".png";
    std::filesystem::create_directories(std::filesystem::path(path).parent_path());
    if (!cv::imwrite(path, mask(i))) throw std::runtime_error(path + ": cannot write the mask");
  }
}

}  // namespace

void writeSilhouettesFromArgs(const ArgParser& parser, const std::vector<std::string>& names,
                              const std::function<cv::Mat(size_t)>& mask) {
  if (parser.has("out-silhouettes")) writeMasks(parser.get("out-silhouettes"), names, mask);
}

void writeViewPriorsFromArgs(const ArgParser& parser, const std::vector<std::string>& names,
                             const ViewSilhouettes& found) {
  if (!parser.has("out-silhouettes") || found.priors.size() != names.size()) return;
  const std::string directory = parser.get("out-silhouettes");
  writeMasks(directory + "/prior", names, [&](size_t i) { return found.priors[i]; });
  writeMasks(directory + "/hull_projection", names,
             [&](size_t i) { return found.hull_projections[i]; });
}

nlohmann::json viewSilhouettesJson(const ViewSilhouettes& report) {
  nlohmann::json json = {{"method", report.method},
                         {"agreement", {{"views", report.agreement}}},
                         {"support_cut_fraction", report.support_fraction},
                         {"support_cut_height", report.support_height},
                         {"up", {report.up_W.x(), report.up_W.y(), report.up_W.z()}},
                         {"time_ms", report.time_ms},
                         {"warnings", report.warnings}};
  if (report.background_agreement >= 0.0) {
    json["agreement"]["background"] = report.background_agreement;
  } else if (!report.background_reason.empty()) {
    json["agreement"]["background_skipped"] = report.background_reason;
  }
  json["support_plane"] = nullptr;
  if (report.support_plane_height) {
    json["support_plane"] = {{"height", *report.support_plane_height},
                             {"share", report.support_plane_share}};
  }
  if (report.ball_centre_W) {
    const Eigen::Vector3d& c = *report.ball_centre_W;
    json["frusta_ball"] = {{"centre", {c.x(), c.y(), c.z()}}, {"radius", report.ball_radius}};
  }
  return json;
}

}  // namespace cli
}  // namespace sift_hull
