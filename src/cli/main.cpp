// sift_hull: the offline program, which links no ROS library (the ROS tools are sift_hull_ros,
// src/ros/tools).
#include "commands.h"

namespace sift_hull {
namespace cli {
namespace {

const Program& offlineProgram() {
  static const Program program{
      "sift_hull",
      {
          {"dataset-info", "summarise a calibrated view set (par, projection list, COLMAP, LLFF)",
           runDatasetInfo},
          {"scene", "render a synthetic scene with exact ground truth", runScene},
          {"match", "match SIFT features of two images and filter them (epipolar, gsc, ...)",
           runMatch},
          {"bench-filters", "time every match filter (the paper's Table 1 and an N sweep)",
           runBenchFilters},
          {"bench-matching", "time SIFT and the descriptor matchers at 1k, 4k and 8k keypoints",
           runBenchMatching},
          {"evaluate-filters", "precision and recall of every filter on Teddy and graf",
           runEvaluateFilters},
          {"hull", "visual hull of calibrated silhouettes: octree, OctoMap and mesh", runHull},
          {"bench-hull", "time the visual hull against dense carving on dino and temple",
           runBenchHull},
      },
      "sift_hull_ros",
      {"bag", "bench-nodes"}};
  return program;
}

}  // namespace
}  // namespace cli
}  // namespace sift_hull

int main(int argc, char** argv) {
  return sift_hull::cli::runMain(sift_hull::cli::offlineProgram(), argc, argv);
}
