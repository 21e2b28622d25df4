// sift_hull_bench: the benchmarks and the evaluation against ground truth, which measure the
// package and write their sections of docs/BENCHMARKS.md and docs/EVALUATION.md. Links no ROS
// library; the nodes' benchmark (bench-nodes) is a command of sift_hull_ros.
#include "bench_commands.h"
#include "commands.h"

int main(int argc, char** argv) {
  using namespace sift_hull::cli;
  static const Program program{
      "sift_hull_bench",
      {{"bench-filters", "time every match filter (the paper's Table 1 and an N sweep)",
        runBenchFilters},
       {"bench-matching", "time SIFT and the descriptor matchers at 1k, 4k and 8k keypoints",
        runBenchMatching},
       {"evaluate-filters", "precision and recall of every filter on Teddy and graf",
        runEvaluateFilters},
       {"bench-hull", "time the visual hull against dense carving on dino and temple",
        runBenchHull}}};
  return runMain(program, argc, argv);
}
