// sift_hull: the user's program, which links no ROS library. The benchmarks and evaluations that
// write parts of docs/ are sift_hull_bench (src/bench), the tools that need ROS sift_hull_ros
// (src/ros/tools).
#include "commands.h"

namespace sift_hull {
namespace cli {
namespace {

const Program& offlineProgram() {
  static const Program program{
      "sift_hull",
      {
          {"dataset-info",
           "summarise a calibrated view set (par, projection list, COLMAP, LLFF, NeRF, IDR)",
           runDatasetInfo},
          {"scene", "render a synthetic scene with exact ground truth", runScene},
          {"match", "match SIFT features of two images and filter them (epipolar, gsc, ...)",
           runMatch},
          {"hull", "visual hull of calibrated silhouettes: octree, OctoMap and mesh", runHull},
      }};
  return program;
}

}  // namespace
}  // namespace cli
}  // namespace sift_hull

int main(int argc, char** argv) {
  return sift_hull::cli::runMain(sift_hull::cli::offlineProgram(), argc, argv);
}
