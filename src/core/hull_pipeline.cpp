#include "sift_hull/hull_pipeline.h"

#include <algorithm>
#include <chrono>
#include <fstream>
#include <stdexcept>

#include "sift_hull/bounding_box.h"

namespace sift_hull {
namespace {

using Clock = std::chrono::steady_clock;

double millisecondsSince(Clock::time_point start) {
  return std::chrono::duration<double, std::milli>(Clock::now() - start).count();
}

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

HullInput loadHullInput(const std::string& calibration_path, const std::string& image_directory,
                        const std::string& mask_directory, const SilhouetteConfig& recipe,
                        const std::vector<std::string>& view_names) {
  const std::vector<CalibratedView> views =
      selectViews(readCalibration(calibration_path), view_names, calibration_path);
  HullInput input;
  input.masks = loadSilhouettes(views, image_directory, mask_directory, recipe);
  for (const CalibratedView& view : views) {
    input.names.push_back(view.name);
    input.cameras.push_back(view.camera);
  }
  return input;
}

HullInput hullInputOf(const std::vector<RenderedView>& views) {
  HullInput input;
  for (const RenderedView& view : views) {
    input.names.push_back(view.view.name);
    input.cameras.push_back(view.view.camera);
    input.masks.push_back(view.mask);
  }
  return input;
}

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

Box3d boundingBoxOf(const std::vector<HullView>& views) {
  std::vector<PinholeCamera> cameras;
  std::vector<SilhouetteBounds> bounds;
  std::vector<std::string> names;
  for (const HullView& view : views) {
    cameras.push_back(view.camera());
    bounds.push_back(view.bounds());
    names.push_back(view.name());
  }
  return hullBoundingBox(cameras, bounds, names);
}

HullResult buildHull(const HullInput& input, const HullConfig& config,
                     const std::optional<Box3d>& box) {
  validate(config);
  HullTimings time;
  const Clock::time_point start = Clock::now();
  std::vector<HullView> views = makeHullViews(input.names, input.cameras, input.masks, config);
  time.distance_ms = millisecondsSince(start);

  Clock::time_point stage = Clock::now();
  const Box3d hull_box = box ? *box : boundingBoxOf(views);
  time.bbox_ms = millisecondsSince(stage);

  stage = Clock::now();
  VisualHull hull(hull_box, config);
  hull.addViews(std::move(views));
  time.octree_ms = millisecondsSince(stage);

  stage = Clock::now();
  TriangleMesh mesh = hull.mesh();
  time.mesh_ms = millisecondsSince(stage);
  time.total_ms = millisecondsSince(start);
  const MeshCheck check = checkMesh(mesh);
  return {hull_box, std::move(hull), std::move(mesh), check, time};
}

}  // namespace sift_hull
