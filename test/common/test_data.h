#pragma once

#include <gtest/gtest.h>
#include <sys/stat.h>

#include <cstdlib>
#include <fstream>
#include <iterator>
#include <string>

#include "sift_hull/hull/hull_pipeline.h"
#include "sift_hull/hull/hull_stream.h"
#include "sift_hull/synthetic/scene.h"

namespace sift_hull {
namespace test {

/// The default scene on a ring of 12 views at 320x240: neighbouring views are 30 degrees apart.
inline SceneConfig smallRing() {
  SceneConfig config;
  config.views = 12;
  config.width_px = 320;
  config.height_px = 240;
  return config;
}

/// A shape seen by `views` cameras of the given layout ("ring" or "sphere"), 320x240, as the
/// hull's input.
inline HullInput sceneHullInput(const std::string& shape, int views,
                                const std::string& layout = "sphere") {
  SceneConfig config;
  config.shape = shape;
  config.views = views;
  config.layout = layout;
  config.width_px = 320;
  config.height_px = 240;
  return hullInputOf(renderScene(config));
}

/// A sphere seen by `views` cameras on a ring, 320x240 (the hull stream tests' input).
inline HullInput ring(int views) { return sceneHullInput("sphere", views, "ring"); }

/// Hull stream settings with the octree depth set, the rest the struct's defaults.
inline HullStreamConfig streamConfig(int depth) {
  HullStreamConfig config;
  config.hull.max_depth = depth;
  return config;
}

/// Root of the real data sets: $SIFT_HULL_DATA, else ../shared/data beside the repository when it
/// exists, else empty.
inline std::string dataRoot() {
  if (const char* env = std::getenv("SIFT_HULL_DATA")) return env;
  const std::string beside_repo = std::string(SIFT_HULL_SOURCE_DIR) + "/../shared/data";
  struct stat info;
  return stat(beside_repo.c_str(), &info) == 0 ? beside_repo : std::string();
}

/// Path of a data set's directory, or empty when it is absent.
inline std::string dataSet(const std::string& name) {
  const std::string root = dataRoot();
  if (root.empty()) return "";
  const std::string path = root + "/" + name;
  struct stat info;
  return stat(path.c_str(), &info) == 0 ? path : std::string();
}

inline bool fileExists(const std::string& path) {
  struct stat info;
  return stat(path.c_str(), &info) == 0;
}

/// A fresh directory under the system's temporary directory (never the working directory).
inline std::string temporaryDirectory() {
  const char* base = std::getenv("TMPDIR");
  std::string pattern = std::string(base ? base : "/tmp") + "/sift_hull_test_XXXXXX";
  if (mkdtemp(pattern.data()) == nullptr) throw std::runtime_error("mkdtemp failed");
  return pattern;
}

/// Runs a shell command line; returns its exit code, its stdout in `out` and its stderr in `err`.
inline int runCommand(const std::string& command_line, std::string* out, std::string* err) {
  const std::string dir = temporaryDirectory();
  const std::string command = command_line + " >" + dir + "/out 2>" + dir + "/err";
  const int status = std::system(command.c_str());
  const auto slurp = [](const std::string& path) {
    std::ifstream in(path);
    return std::string(std::istreambuf_iterator<char>(in), {});
  };
  *out = slurp(dir + "/out");
  *err = slurp(dir + "/err");
  return WEXITSTATUS(status);
}

#ifdef SIFT_HULL_EXECUTABLE
/// Runs the offline program sift_hull with `arguments` (shell words), as runCommand.
inline int runProgram(const std::string& arguments, std::string* out, std::string* err) {
  return runCommand(std::string(SIFT_HULL_EXECUTABLE) + " " + arguments, out, err);
}

/// A test suite sharing one scene written by `sift_hull scene` (8 views, 320x240) in the
/// directory `scene_`, for the command-line tests.
class WrittenSceneSuite : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    scene_ = new std::string(temporaryDirectory());
    std::string out, err;
    ASSERT_EQ(runProgram("scene --out " + *scene_ + " --views 8 --size 320x240", &out, &err), 0)
        << err;
  }
  static void TearDownTestSuite() {
    delete scene_;
    scene_ = nullptr;
  }

  inline static std::string* scene_ = nullptr;
};
#endif

#ifdef SIFT_HULL_BENCH_EXECUTABLE
/// Runs the benchmarks' program sift_hull_bench (bench-filters, bench-matching, evaluate-filters,
/// bench-hull), as runCommand.
inline int runBenchProgram(const std::string& arguments, std::string* out, std::string* err) {
  return runCommand(std::string(SIFT_HULL_BENCH_EXECUTABLE) + " " + arguments, out, err);
}
#endif

#ifdef SIFT_HULL_ROS_EXECUTABLE
/// Runs the ROS tools' program sift_hull_ros (bag, bench-nodes), as runCommand.
inline int runRosProgram(const std::string& arguments, std::string* out, std::string* err) {
  return runCommand(std::string(SIFT_HULL_ROS_EXECUTABLE) + " " + arguments, out, err);
}
#endif

}  // namespace test
}  // namespace sift_hull

/// Skips the current test, saying why, when a real data set is not available.
#define SIFT_HULL_REQUIRE_DATA(dir_variable, name)                                          \
  const std::string dir_variable = ::sift_hull::test::dataSet(name);                        \
  if (dir_variable.empty()) {                                                               \
    GTEST_SKIP() << "data set '" << name << "' not found: set SIFT_HULL_DATA or put it in " \
                 << "../shared/data";                                                       \
  }
