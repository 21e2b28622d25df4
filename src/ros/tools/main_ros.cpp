// sift_hull_ros: the tools that need ROS (bags, the nodes' benchmark, the files derived from
// their settings), apart from the user's program sift_hull and the benchmarks' sift_hull_bench,
// which link no ROS library.
#include "commands.h"

namespace sift_hull {
namespace cli {

int runBag(const std::vector<std::string>& args);
int runBenchNodes(const std::vector<std::string>& args);
int runSettings(const std::vector<std::string>& args);

}  // namespace cli
}  // namespace sift_hull

int main(int argc, char** argv) {
  using namespace sift_hull::cli;
  static const Program program{
      "sift_hull_ros",
      {{"bag", "write calibrated views as a ROS bag that drives both nodes", runBag},
       {"bench-nodes", "time the matcher and hull nodes as processes on topic streams",
        runBenchNodes},
       {"settings", "write or check the parameter files and tables derived from the settings",
        runSettings}}};
  return runMain(program, argc, argv);
}
