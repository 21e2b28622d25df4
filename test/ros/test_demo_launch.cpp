// launch/demo.launch end to end: a synthetic scene's bag played through both nodes (as nodes and
// as nodelets), the results saved by save_results once the last view is in, and the saved hull
// compared with the offline `sift_hull hull` of the same views; with photo_carve:=true the bag's
// images reach the hull node and the saved cloud carries colour.

#include <gtest/gtest.h>
#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <opencv2/imgcodecs.hpp>

#include "common/test_data.h"
#include "sift_hull/filters/filter.h"
#include "sift_hull/hull/mesh.h"
#include "sift_hull/io/ply.h"
#include "tools/free_port.h"

namespace sift_hull {
namespace {

constexpr int kViews = 8;
constexpr int kDepth = 6;

class DemoLaunch : public ::testing::TestWithParam<bool> {
 protected:
  static void SetUpTestSuite() {
    dir_ = test::temporaryDirectory();
    std::string out, err;
    ASSERT_EQ(test::runProgram(
                  "scene --out " + dir_ + " --views " + std::to_string(kViews) + " --size 320x240",
                  &out, &err),
              0)
        << err;
    const std::string views = " --calib " + dir_ + "/scene_par.txt --images " + dir_ +
                              " --silhouettes " + dir_ + "/masks";
    ASSERT_EQ(
        test::runRosProgram("bag" + views + " --rate 8 --out " + dir_ + "/scene.bag", &out, &err),
        0)
        << err;
    ASSERT_EQ(test::runProgram("hull" + views + " --max-depth " + std::to_string(kDepth) +
                                   " --out-mesh " + dir_ + "/offline.ply",
                               &out, &err),
              0)
        << err;
  }

  /// Runs demo.launch with a master of its own on a port no other test uses; returns its exit code.
  static int runDemoLaunch(const std::string& out_dir, bool nodelets, std::string* log,
                           const std::string& more = "") {
    const int port = freeTcpPort();
    const std::string uri = "http://localhost:" + std::to_string(port);
    const std::string command = "ROS_MASTER_URI=" + uri + " timeout 150 roslaunch -p " +
                                std::to_string(port) + " sift_hull demo.launch bag:=" + dir_ +
                                "/scene.bag out:=" + out_dir +
                                " max_depth:=" + std::to_string(kDepth) +
                                " nodelets:=" + (nodelets ? "true" : "false") + more;
    std::string err;
    const int status = test::runCommand(command, log, &err);
    *log += err;
    return status;
  }

  static std::string dir_;
};
std::string DemoLaunch::dir_;

TEST_P(DemoLaunch, PlaysTheBagThroughBothNodesAndSavesTheResults) {
  const std::string out = dir_ + (GetParam() ? "/nodelets" : "/nodes");
  std::string log;
  ASSERT_EQ(runDemoLaunch(out, GetParam(), &log), 0) << log;
  // A complete save ends the launch as Ctrl-C does, not by a required node's death.
  EXPECT_EQ(log.find("REQUIRED process"), std::string::npos) << log;
  EXPECT_NE(log.find("ending the launch"), std::string::npos) << log;
  std::ifstream summary_file(out + "/summary.json");
  ASSERT_TRUE(summary_file) << "no summary.json; roslaunch said:\n" << log;
  const nlohmann::json summary = nlohmann::json::parse(summary_file);
  EXPECT_TRUE(summary["complete"].get<bool>()) << summary.dump(2);
  EXPECT_EQ(summary["hull"]["views_in_bag"], kViews);
  EXPECT_EQ(summary["matcher"]["pairs_matched"], kViews);
  // The matcher's default filter; its keep count is under its own name.
  const auto& kept = summary["matcher"]["last_pair"]["kept"];
  ASSERT_TRUE(kept.contains(kDefaultFilter)) << summary.dump(2);
  EXPECT_GT(kept[kDefaultFilter].get<int>(), 20);
  for (const char* key : {"octree", "mesh", "point_cloud", "matches_image"}) {
    const std::string path = summary["files"][key];
    EXPECT_TRUE(std::filesystem::file_size(path) > 0) << key;
  }
  EXPECT_FALSE(cv::imread(summary["files"]["matches_image"]).empty());

  // The node's hull lies in another box than the offline one (it is fixed by the first views
  // whose LP is bounded), so the volumes agree to the sampling of a depth-6 grid, not exactly.
  const TriangleMesh node_mesh = readPly(summary["files"]["mesh"]);
  const TriangleMesh offline_mesh = readPly(dir_ + "/offline.ply");
  EXPECT_TRUE(checkMesh(node_mesh).watertight);
  EXPECT_NEAR(meshVolume(node_mesh), meshVolume(offline_mesh), 0.05 * meshVolume(offline_mesh));
}

TEST_F(DemoLaunch, PhotoCarveGivesTheHullNodeTheBagsImagesAndTheSavedCloudItsColours) {
  const std::string out = dir_ + "/photo";
  std::string log;
  ASSERT_EQ(runDemoLaunch(out, false, &log, " photo_carve:=true"), 0) << log;
  std::ifstream summary_file(out + "/summary.json");
  ASSERT_TRUE(summary_file) << "no summary.json; roslaunch said:\n" << log;
  const nlohmann::json summary = nlohmann::json::parse(summary_file);
  EXPECT_TRUE(summary["complete"].get<bool>()) << summary.dump(2);
  EXPECT_EQ(log.find("photo carving leaves out"), std::string::npos)
      << "a view without its photograph:\n"
      << log;
  // The PCD's header names its fields: the centres with PCL's rgb.
  std::ifstream pcd(summary["files"]["point_cloud"].get<std::string>());
  std::string line;
  bool rgb = false;
  while (std::getline(pcd, line) && line.rfind("DATA", 0) != 0) {
    if (line.rfind("FIELDS", 0) == 0) rgb = line.find(" rgb") != std::string::npos;
  }
  EXPECT_TRUE(rgb) << "the saved cloud has no rgb field";
}

INSTANTIATE_TEST_SUITE_P(NodesAndNodelets, DemoLaunch, ::testing::Bool(),
                         [](const auto& info) { return info.param ? "Nodelets" : "Nodes"; });

}  // namespace
}  // namespace sift_hull
