#include <octomap/OcTree.h>

#include <opencv2/imgcodecs.hpp>
#include <sstream>

#include "args.h"
#include "bench_timing.h"
#include "commands.h"
#include "hull_options.h"
#include "sift_hull/eval/mesh_render.h"
#include "sift_hull/hull/hull_config.h"
#include "sift_hull/hull/hull_octomap.h"
#include "sift_hull/hull/hull_pipeline.h"
#include "sift_hull/io/ply.h"

namespace sift_hull {
namespace cli {
namespace {

void writeOutputs(const ArgParser& parser, const HullResult& result,
                  const octomap::OcTree& octree) {
  if (parser.has("out-mesh")) writePly(parser.get("out-mesh"), result.mesh);
  if (parser.has("out-octree")) writeOctomap(octree, parser.get("out-octree"));
  if (parser.has("out-render")) {
    const std::string path = parser.get("out-render");
    if (!cv::imwrite(path, renderTurntable(result.mesh, 4, cv::Size(480, 480)))) {
      throw std::runtime_error(path + ": cannot write the image");
    }
  }
}

std::string hullText(const nlohmann::json& result) {
  std::ostringstream text;
  text << result["views"] << " views, depth " << result["max_depth"] << " (voxel "
       << result["resolution"] << "), box " << result["bbox"]["min"] << " .. "
       << result["bbox"]["max"] << "\noccupied leaves " << result["occupied_leaves"] << ", mesh "
       << result["mesh"]["vertices"] << " vertices, " << result["mesh"]["faces"]
       << " faces, watertight " << result["mesh"]["watertight"] << "\ntime (ms) "
       << result["time_ms"].dump() << "\nreprojection IoU min " << result["reprojection_iou"]["min"]
       << ", mean " << result["reprojection_iou"]["mean"] << '\n';
  return text.str();
}

}  // namespace

int runHull(const std::vector<std::string>& args) {
  ArgParser parser("hull",
                   "Visual hull of calibrated silhouettes: bounding box by linear programming,\n"
                   "octree carving with signed distances, marching cubes.");
  addViewSetOptions(&parser);
  addHullOptions(&parser);
  parser.addOption("out-mesh", "PLY", "write the mesh (binary PLY, world coordinates)");
  parser.addOption("out-octree", "BT", "write the OctoMap (.bt)");
  parser.addOption("out-render", "PNG", "write shaded renderings of the mesh");
  parser.addFlag("json", "print the result as one JSON object");
  if (!parser.parse(args)) return 0;

  const HullConfig config = hullConfigFromArgs(parser);
  const HullResult result = buildHull(viewSetFromArgs(parser), config, boxFromArgs(parser));
  const double hull_peak_mib = peakMemoryMiB();
  const std::unique_ptr<octomap::OcTree> octree = toOctomap(result.hull);
  const ReprojectionIoU iou = reprojectionIoU(result.mesh, result.hull.views());
  writeOutputs(parser, result, *octree);
  nlohmann::json json = hullJson(result, octree->getNumLeafNodes(), iou);
  json["peak_memory_mib"] = {{"through_hull", hull_peak_mib}, {"total", peakMemoryMiB()}};
  printResult(parser.flag("json"), json, hullText(json));
  return 0;
}

}  // namespace cli
}  // namespace sift_hull
