// The visual hull on the real Middlebury rings (skipped when the data is absent) and the `hull`
// command on a synthetic scene (always runs).

#include <gtest/gtest.h>

#include <nlohmann/json.hpp>

#include "common/test_data.h"
#include "sift_hull/eval/hull_evaluation.h"
#include "sift_hull/hull/hull_config.h"
#include "sift_hull/hull/hull_pipeline.h"
#include "sift_hull/hull/silhouette.h"
#include "sift_hull/io/ply.h"
#include "sift_hull/io/view_list.h"

namespace sift_hull {
namespace {

struct RingCase {
  std::string directory, calibration, view_list;
  double threshold;  ///< silhouette threshold, as bench-hull uses
  double min_iou_floor, mean_iou_floor;
};

HullResult carveRing(const RingCase& ring, int depth) {
  const std::string dir = test::dataSet(ring.directory);
  const std::vector<std::string> views = ring.view_list.empty()
                                             ? std::vector<std::string>{}
                                             : readViewList(dir + "/" + ring.view_list);
  HullConfig config;
  config.max_depth = depth;
  SilhouetteConfig recipe;
  recipe.silhouette_method = "threshold";
  recipe.threshold = ring.threshold;
  return buildHull(loadHullInput(dir + "/" + ring.calibration, dir, "", recipe, views), config);
}

class RingHull : public ::testing::TestWithParam<RingCase> {};

TEST_P(RingHull, CarvesAWatertightHullThatReprojectsOntoTheSilhouettes) {
  if (test::dataSet(GetParam().directory).empty()) {
    GTEST_SKIP() << GetParam().directory << " not found under SIFT_HULL_DATA or ../shared/data";
  }
  const HullResult result = carveRing(GetParam(), 7);
  EXPECT_TRUE(result.mesh_check.watertight);
  const ReprojectionIoU iou = reprojectionIoU(result.mesh, result.hull.views());
  EXPECT_GE(iou.min, GetParam().min_iou_floor);
  EXPECT_GE(iou.mean, GetParam().mean_iou_floor);
}

INSTANTIATE_TEST_SUITE_P(
    Middlebury, RingHull,
    ::testing::Values(
        // dino, 15 good-silhouette views, depth 7: measured IoU min 0.9746, mean 0.9864.
        RingCase{"middlebury_mvs_dinoSparseRing", "dinoSR_par.txt",
                 "dinoSR_good_silhouette_images.txt", 0.19, 0.97, 0.98},
        // temple, all 16 views, depth 7: measured IoU min 0.9662, mean 0.9820.
        RingCase{"middlebury_mvs_templeSparseRing", "templeSR_par.txt", "", 0.25, 0.96, 0.975}),
    [](const auto& info) {
      return info.param.calibration.substr(0, info.param.calibration.find("SR"));
    });

TEST(HullCommand, WritesMeshOctreeAndRenderOfASyntheticScene) {
  const std::string dir = test::temporaryDirectory();
  std::string out, err;
  ASSERT_EQ(test::runProgram("scene --out " + dir + " --shape sphere --views 8 --size 320x240",
                             &out, &err),
            0)
      << err;
  ASSERT_EQ(test::runProgram(
                "hull --calib " + dir + "/scene_par.txt --images " + dir + " --silhouettes " + dir +
                    "/masks --max-depth 6 --json --out-mesh " + dir + "/hull.ply --out-octree " +
                    dir + "/hull.bt --out-render " + dir + "/hull.png",
                &out, &err),
            0)
      << err;
  const nlohmann::json result = nlohmann::json::parse(out);
  EXPECT_EQ(result["views"], 8);
  EXPECT_EQ(result["max_depth"], 6);
  EXPECT_TRUE(result["mesh"]["watertight"].get<bool>());
  EXPECT_GT(result["occupied_leaves"].get<int>(), 0);
  EXPECT_GE(result["reprojection_iou"]["min"].get<double>(), 0.97);
  for (const char* key : {"distance", "bbox", "octree", "mesh", "total"}) {
    EXPECT_TRUE(result["time_ms"].contains(key)) << key;
  }
  EXPECT_EQ(readPly(dir + "/hull.ply").faces.size(), result["mesh"]["faces"].get<size_t>());
  for (const char* file : {"/hull.bt", "/hull.png"}) {
    EXPECT_TRUE(test::fileExists(dir + file)) << file;
  }
}

TEST(HullCommand, FlagsAreTheSettingNamesAndOldNamesAreRefused) {
  const std::string dir = test::temporaryDirectory();
  std::string out, err;
  ASSERT_EQ(test::runProgram("scene --out " + dir + " --views 8 --size 320x240", &out, &err), 0)
      << err;
  const std::string hull =
      "hull --calib " + dir + "/scene_par.txt --images " + dir + " --threshold 0.1 --json ";
  const auto run = [&](const std::string& flags, std::string* errors) {
    std::string json;
    EXPECT_EQ(test::runProgram(hull + flags, &json, errors), 0) << *errors;
    return nlohmann::json::parse(json);  // stdout holds the JSON object alone
  };
  std::string new_err;
  const nlohmann::json with_new =
      run("--max-depth 5 --distance-slack-px 3 --dilate-px 3 --erode-px 1", &new_err);
  const nlohmann::json with_defaults = run("--max-depth 5", &err);
  EXPECT_EQ(with_new["max_depth"], 5);
  // measured: 1607 and 1537 leaves
  EXPECT_NE(with_new["occupied_leaves"], with_defaults["occupied_leaves"]);
  std::string json;
  for (const char* old : {"--depth 5", "--slack 3", "--dilate 3", "--erode 1"}) {
    EXPECT_EQ(test::runProgram(hull + old, &json, &err), 2) << old;
  }
}

TEST(HullCommand, ReportsTooFewViewsClearly) {
  const std::string dir = test::temporaryDirectory();
  std::string out, err;
  ASSERT_EQ(test::runProgram("scene --out " + dir + " --shape sphere --views 4 --size 320x240",
                             &out, &err),
            0);
  EXPECT_EQ(test::runProgram("hull --calib " + dir + "/scene_par.txt --images " + dir +
                                 " --views view_0000.png --max-depth 5",
                             &out, &err),
            1);
  EXPECT_NE(err.find("at least two are needed"), std::string::npos) << err;
}

}  // namespace
}  // namespace sift_hull
