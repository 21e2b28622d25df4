#include "hull_options.h"

#include <sstream>

namespace sift_hull {
namespace cli {
namespace {

nlohmann::json vectorJson(const Eigen::Vector3d& v) { return {v.x(), v.y(), v.z()}; }

}  // namespace

void addHullOptions(ArgParser* parser) {
  const HullConfig defaults;
  std::ostringstream slack;
  slack << defaults.distance_slack_px;
  parser->addOption("depth", "L", "octree depth: resolution = cube edge / 2^L",
                    std::to_string(defaults.max_depth));
  parser->addFlag("carve-outside-image", "views carve what they see outside their image");
  parser->addOption("slack", "PX", "margin added to a cell's projected radius, in pixels",
                    slack.str());
  parser->addOption("threads", "N", "threads for distance transforms, carving and meshing",
                    std::to_string(defaults.threads));
  parser->addOption("box", "XMIN,YMIN,ZMIN,XMAX,YMAX,ZMAX",
                    "bounding box in world units instead of solving the LP");
}

HullConfig hullConfigFromArgs(const ArgParser& parser) {
  HullConfig config;
  config.max_depth = parser.getInt("depth");
  config.carve_outside_image = parser.flag("carve-outside-image");
  config.distance_slack_px = parser.getDouble("slack");
  config.threads = parser.getInt("threads");
  try {
    validate(config);
  } catch (const std::invalid_argument& e) {
    throw UsageError(e.what());
  }
  return config;
}

std::optional<Box3d> boxFromArgs(const ArgParser& parser) {
  if (!parser.has("box")) return std::nullopt;
  std::istringstream in(parser.get("box"));
  double values[6];
  char comma = ',';
  for (int i = 0; i < 6; ++i) {
    if ((i > 0 && !(in >> comma)) || comma != ',' || !(in >> values[i])) {
      throw UsageError("--box expects six comma-separated numbers");
    }
  }
  Box3d box;
  box.min_W = Eigen::Vector3d(values[0], values[1], values[2]);
  box.max_W = Eigen::Vector3d(values[3], values[4], values[5]);
  if (!(box.size().array() > 0.0).all()) throw UsageError("--box: each max must exceed its min");
  return box;
}

nlohmann::json hullJson(const HullResult& result, size_t occupied_leaves,
                        const ReprojectionIoU& iou) {
  const HullTimings& time = result.time;
  return {{"views", result.hull.views().size()},
          {"bbox", {{"min", vectorJson(result.box.min_W)}, {"max", vectorJson(result.box.max_W)}}},
          {"depth", result.hull.cube().depth},
          {"resolution", result.hull.cube().resolution_m},
          {"occupied_leaves", occupied_leaves},
          {"mesh",
           {{"vertices", result.mesh.vertices_W.size()},
            {"faces", result.mesh.faces.size()},
            {"watertight", result.mesh_check.watertight}}},
          {"time_ms",
           {{"distance", time.distance_ms},
            {"bbox", time.bbox_ms},
            {"octree", time.octree_ms},
            {"mesh", time.mesh_ms},
            {"total", time.total_ms}}},
          {"reprojection_iou", {{"min", iou.min}, {"mean", iou.mean}}}};
}

}  // namespace cli
}  // namespace sift_hull
