// sift_hull: the user's program, which links no ROS library. The benchmarks and evaluations that
// write parts of docs/ are sift_hull_bench (src/bench), the tools that need ROS sift_hull_ros
// (src/ros/tools).
#include <malloc.h>

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
  // A photo set allocates and frees image-sized buffers view after view. Above glibc's mmap
  // threshold (at most 32 MiB by itself) each one is mapped afresh and its pages faulted in and
  // zeroed, then unmapped: a quarter of the time of 40 photographs of 12 MP. Kept in the heap
  // up to 1 GiB, they are reused; this is a program that ends when its command is done.
  mallopt(M_MMAP_THRESHOLD, 1 << 30);
  mallopt(M_TRIM_THRESHOLD, 1 << 30);
  return sift_hull::cli::runMain(sift_hull::cli::offlineProgram(), argc, argv);
}
