#include "sift_hull/io/view_list.h"

#include <algorithm>
#include <fstream>
#include <stdexcept>

#include "sift_hull/io/calibration.h"
#include "sift_hull/io/images.h"

namespace sift_hull {
namespace {

std::vector<CalibratedView> selectViews(const std::vector<CalibratedView>& all,
                                        const std::vector<std::string>& names,
                                        const std::string& calibration_path) {
  if (names.empty()) return all;
  for (const std::string& name : names) {
    const auto named = [&](const CalibratedView& view) { return view.name == name; };
    if (std::none_of(all.begin(), all.end(), named)) {
      throw std::runtime_error(calibration_path + ": no view named '" + name + "'");
    }
  }
  std::vector<CalibratedView> chosen;
  for (const CalibratedView& view : all) {
    if (std::find(names.begin(), names.end(), view.name) != names.end()) chosen.push_back(view);
  }
  return chosen;
}

}  // namespace

std::vector<std::string> readViewList(const std::string& path) {
  std::ifstream in(path);
  if (!in) throw std::runtime_error(path + ": view list missing or unreadable");
  std::vector<std::string> names;
  std::string line;
  while (std::getline(in, line)) {
    line.erase(std::find(line.begin(), line.end(), '#'), line.end());
    const auto first = line.find_first_not_of(" \t\r");
    if (first == std::string::npos) continue;
    names.push_back(line.substr(first, line.find_last_not_of(" \t\r") - first + 1));
  }
  return names;
}

std::vector<CalibratedView> hullViews(const std::string& calibration_path,
                                      const std::string& image_directory,
                                      const std::vector<std::string>& view_names) {
  return selectViews(readCalibrationWithImages(calibration_path, image_directory), view_names,
                     calibration_path);
}

namespace {

void addCameras(const std::vector<CalibratedView>& views, HullInput* input) {
  for (const CalibratedView& view : views) {
    input->names.push_back(view.name);
    input->cameras.push_back(view.camera);
  }
}

}  // namespace

HullInput loadHullInput(const std::string& calibration_path, const std::string& image_directory,
                        const std::string& mask_directory, const SilhouetteConfig& recipe,
                        const std::vector<std::string>& view_names, ViewSilhouettes* report) {
  const std::vector<CalibratedView> views =
      hullViews(calibration_path, image_directory, view_names);
  HullInput input;
  input.masks = loadSilhouettes(views, image_directory, mask_directory, recipe, report);
  addCameras(views, &input);
  return input;
}

HullInput loadRunLengthHullInput(const std::string& calibration_path,
                                 const std::string& image_directory,
                                 const std::string& mask_directory, const SilhouetteConfig& recipe,
                                 const std::vector<std::string>& view_names,
                                 ViewSilhouettes* report) {
  const std::vector<CalibratedView> views =
      hullViews(calibration_path, image_directory, view_names);
  HullInput input;
  input.run_length_masks =
      loadRunLengthSilhouettes(views, image_directory, mask_directory, recipe, report);
  addCameras(views, &input);
  return input;
}

}  // namespace sift_hull
