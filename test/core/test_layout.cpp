// The layout's rules (docs/ARCHITECTURE.md), checked on the source tree and the programs: each
// stage includes only the stages below it, the core, the user's program sift_hull and the
// benchmarks' sift_hull_bench include and link nothing of ROS, sift_hull includes nothing of
// sift_hull_bench and sends its commands there, no source file grows past 450 lines, and the
// catkin package lints clean.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <iterator>
#include <map>
#include <regex>
#include <set>
#include <string>
#include <vector>

#include "common/test_data.h"

namespace sift_hull {
namespace {

namespace fs = std::filesystem;

const fs::path kRoot = SIFT_HULL_SOURCE_DIR;

/// The stages each stage may include (itself always).
const std::map<std::string, std::set<std::string>>& allowedIncludes() {
  static const std::map<std::string, std::set<std::string>> allowed = {
      {"geometry", {}},
      {"features", {"geometry"}},
      {"filters", {"geometry", "features"}},
      {"hull", {"geometry"}},
      {"refine", {"geometry", "hull"}},
      {"mvs", {"geometry", "hull"}},
      {"draw", {"geometry", "features", "filters"}},
      {"pipeline", {"geometry", "features", "filters", "hull", "refine"}},
      {"io", {"geometry", "features", "filters", "hull"}},
      {"synthetic", {"geometry", "features", "filters", "hull", "io"}},
      {"eval", {"geometry", "features", "filters", "hull", "refine", "io"}},
  };
  return allowed;
}

std::vector<fs::path> sourcesUnder(const fs::path& directory) {
  std::vector<fs::path> files;
  if (!fs::exists(directory)) return files;
  for (const auto& entry : fs::recursive_directory_iterator(directory)) {
    const std::string extension = entry.path().extension().string();
    if (extension == ".h" || extension == ".cpp") files.push_back(entry.path());
  }
  return files;
}

/// The quoted and angled includes of a file.
std::vector<std::string> includesOf(const fs::path& file) {
  std::ifstream in(file);
  std::vector<std::string> includes;
  const std::regex include(R"(^\s*#\s*include\s*[<"]([^>"]+)[>"])");
  std::smatch match;
  for (std::string line; std::getline(in, line);) {
    if (std::regex_search(line, match, include)) includes.push_back(match[1]);
  }
  return includes;
}

/// The stage of a file under include/sift_hull/<stage>/ or src/core/<stage>/ (empty otherwise).
std::string stageOf(const fs::path& file) {
  const fs::path relative = fs::relative(file, kRoot);
  auto part = relative.begin();
  const std::string top = (part++)->string();
  const std::string second = part == relative.end() ? "" : (part++)->string();
  if ((top == "include" && second == "sift_hull") || (top == "src" && second == "core")) {
    if (part == relative.end() || std::next(part) == relative.end()) return "";  // no folder
    return part->string();
  }
  return "";
}

/// A header of ROS, of a ROS package, of the package's generated messages (sift_hull/Foo.h), or
/// of its ROS library, nodes or tools (src/ros).
bool isRosHeader(const std::string& include) {
  static const std::regex ros(
      R"(^(ros|rosbag|sensor_msgs|std_msgs|geometry_msgs|visualization_msgs|tf2[a-z_]*|cv_bridge|)"
      R"(image_transport|nodelet|pluginlib|pcl_conversions|dynamic_reconfigure|message_filters|)"
      R"(diagnostic_[a-z_]+|std_srvs|lib|nodes|nodelets|tools)/|^sift_hull/[A-Z]\w*\.h$|\.\./ros/)");
  return std::regex_search(include, ros);
}

std::vector<fs::path> coreFiles() {
  std::vector<fs::path> files = sourcesUnder(kRoot / "include" / "sift_hull");
  for (const fs::path& file : sourcesUnder(kRoot / "src" / "core")) files.push_back(file);
  return files;
}

TEST(LayoutTest, EachStageIncludesOnlyTheStagesBelowIt) {
  const std::regex stage_include(R"(^(?:sift_hull/)?([a-z_]+)/[a-z_]+\.h$)");
  std::set<std::string> stages;
  for (const fs::path& file : coreFiles()) {
    const std::string stage = stageOf(file);
    if (stage.empty() || stage == "common" || fs::is_directory(file)) continue;
    ASSERT_TRUE(allowedIncludes().count(stage)) << file << ": a folder the layout does not know";
    stages.insert(stage);
    for (const std::string& include : includesOf(file)) {
      std::smatch match;
      if (!std::regex_match(include, match, stage_include)) continue;
      const std::string other = match[1];
      if (other == stage || other == "common" || !allowedIncludes().count(other)) continue;
      EXPECT_TRUE(allowedIncludes().at(stage).count(other))
          << fs::relative(file, kRoot) << " (" << stage << ") includes " << include << " (" << other
          << ")";
    }
  }
  EXPECT_EQ(stages.size(), allowedIncludes().size()) << "a stage folder has gone missing";
}

TEST(LayoutTest, RosHeadersAreRecognised) {
  for (const char* include :
       {"ros/ros.h", "sensor_msgs/Image.h", "tf2_ros/buffer.h", "sift_hull/Octomap.h",
        "lib/conversions.h", "tools/free_port.h", "../ros/tools/free_port.h"}) {
    EXPECT_TRUE(isRosHeader(include)) << include;
  }
  for (const char* include : {"sift_hull/hull/octree.h", "sift_hull/limits.h", "opencv2/core.hpp",
                              "octomap/OcTree.h", "common/parallel.h"}) {
    EXPECT_FALSE(isRosHeader(include)) << include;
  }
}

TEST(LayoutTest, TheCoreAndTheOfflineProgramsIncludeNoRosHeader) {
  std::vector<fs::path> files = coreFiles();
  for (const char* program : {"cli", "bench"}) {
    for (const fs::path& file : sourcesUnder(kRoot / "src" / program)) files.push_back(file);
  }
  ASSERT_GT(files.size(), 50u);
  for (const fs::path& file : files) {
    for (const std::string& include : includesOf(file)) {
      EXPECT_FALSE(isRosHeader(include)) << fs::relative(file, kRoot) << " includes " << include;
    }
  }
}

TEST(LayoutTest, TheUserProgramIncludesNothingOfTheBenchmarks) {
  std::set<std::string> bench_headers;
  for (const fs::path& file : sourcesUnder(kRoot / "src" / "bench")) {
    if (file.extension() == ".h") bench_headers.insert(file.filename().string());
  }
  ASSERT_TRUE(bench_headers.count("pair_data.h")) << "src/bench has moved";
  const std::vector<fs::path> files = sourcesUnder(kRoot / "src" / "cli");
  ASSERT_GT(files.size(), 20u);
  for (const fs::path& file : files) {
    for (const std::string& include : includesOf(file)) {
      EXPECT_FALSE(bench_headers.count(fs::path(include).filename().string()) ||
                   include.find("bench/") != std::string::npos)
          << fs::relative(file, kRoot) << " includes " << include;
    }
  }
}

TEST(LayoutTest, TheOfflineProgramLinksNoRosLibrary) {
  for (const char* program : {SIFT_HULL_EXECUTABLE, SIFT_HULL_BENCH_EXECUTABLE}) {
    std::string out, err;
    ASSERT_EQ(test::runCommand("ldd " + std::string(program), &out, &err), 0) << err;
    ASSERT_NE(out.find("libsift_hull_core"), std::string::npos) << out;  // ldd read the program
    for (const char* library : {"libroscpp", "librosbag", "libcv_bridge", "libtf2", "librostime"}) {
      EXPECT_EQ(out.find(library), std::string::npos) << program << " links " << library << ":\n"
                                                      << out;
    }
  }
}

TEST(LayoutTest, TheOfflineProgramNamesWhereTheRosCommandsWent) {
  for (const char* command : {"bag", "bench-nodes"}) {
    std::string out, err;
    EXPECT_EQ(test::runProgram(command, &out, &err), 2) << command;
    EXPECT_NE(err.find("run 'sift_hull_ros " + std::string(command) + "'"), std::string::npos)
        << err;
    EXPECT_EQ(test::runBenchProgram(command, &out, &err), 2) << command;
    EXPECT_NE(err.find("run 'sift_hull_ros " + std::string(command) + "'"), std::string::npos)
        << err;
  }
}

TEST(LayoutTest, TheBenchmarksAreCommandsOfSiftHullBenchNotOfSiftHull) {
  for (const char* command :
       {"bench-filters", "bench-matching", "evaluate-filters", "bench-hull"}) {
    std::string out, err;
    EXPECT_EQ(test::runProgram(command, &out, &err), 2) << command;
    EXPECT_NE(err.find("is a command of sift_hull_bench, not of sift_hull: run 'sift_hull_bench " +
                       std::string(command) + "'"),
              std::string::npos)
        << err;
    EXPECT_EQ(test::runBenchProgram(std::string(command) + " --help", &out, &err), 0) << err;
    EXPECT_EQ(out.rfind("usage: sift_hull_bench " + std::string(command), 0), 0u) << out;
    EXPECT_EQ(test::runBenchProgram(std::string(command) + " --no-such-option", &out, &err), 2);
    EXPECT_NE(err.find("(see 'sift_hull_bench " + std::string(command) + " --help')"),
              std::string::npos)
        << err;
  }
  for (const char* command : {"dataset-info", "scene", "match", "hull"}) {
    std::string out, err;
    EXPECT_EQ(test::runBenchProgram(command, &out, &err), 2) << command;
    EXPECT_NE(err.find("run 'sift_hull " + std::string(command) + "'"), std::string::npos) << err;
  }
  std::string out, err;
  EXPECT_EQ(test::runBenchProgram("", &out, &err), 2);
  EXPECT_EQ(err.rfind("usage: sift_hull_bench <command>", 0), 0u) << err;
  EXPECT_EQ(test::runBenchProgram("no-such-command", &out, &err), 2);
  EXPECT_NE(err.find("unknown command 'no-such-command'"), std::string::npos) << err;
}

TEST(LayoutTest, NoSourceFileExceeds450Lines) {
  std::vector<fs::path> files;
  for (const char* directory : {"include", "src", "test"}) {
    for (const fs::path& file : sourcesUnder(kRoot / directory)) files.push_back(file);
  }
  ASSERT_GT(files.size(), 100u);
  for (const fs::path& file : files) {
    std::ifstream in(file);
    size_t lines = 0;
    for (std::string line; std::getline(in, line);) ++lines;
    EXPECT_LE(lines, 450u) << fs::relative(file, kRoot);
  }
}

/// catkin_lint (scripts/apt-packages.txt) finds no problem in the package, warnings included;
/// what it cannot see is explained where CMakeLists.txt tells it to ignore it.
TEST(LayoutTest, TheCatkinPackageLintsClean) {
  std::string out, err;
  if (test::runCommand("command -v catkin_lint", &out, &err) != 0) {
    GTEST_SKIP() << "catkin_lint is not installed";
  }
  EXPECT_EQ(test::runCommand("catkin_lint --strict " + kRoot.string(), &out, &err), 0)
      << out << err;
}

}  // namespace
}  // namespace sift_hull
