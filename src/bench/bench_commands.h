#pragma once

#include <string>
#include <vector>

namespace sift_hull {
namespace cli {

/// The commands of sift_hull_bench (main_bench.cpp), as Command::run.
int runBenchFilters(const std::vector<std::string>& args);
int runBenchMatching(const std::vector<std::string>& args);
int runEvaluateFilters(const std::vector<std::string>& args);
int runBenchHull(const std::vector<std::string>& args);

}  // namespace cli
}  // namespace sift_hull
