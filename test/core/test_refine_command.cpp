// `sift_hull hull --refine-with-matches` as users run it: a concave scene on disk, SIFT and dense
// matches, the JSON's counts and the comparison with the true solid, and refusals of bad settings.

#include <gtest/gtest.h>

#include <iostream>
#include <nlohmann/json.hpp>
#include <string>

#include "common/test_data.h"
#include "sift_hull/io/ply.h"
#include "sift_hull/mvs/photo_carving.h"

namespace sift_hull {
namespace {

/// The cup, 20 views on a sphere at 320x240, written once by `sift_hull scene`.
const std::string& cupScene() {
  static const std::string directory = [] {
    const std::string dir = test::temporaryDirectory() + "/cup";
    std::string out, err;
    EXPECT_EQ(
        test::runProgram("scene --shape cup --layout sphere --views 20 --size 320x240 --out " + dir,
                         &out, &err),
        0)
        << err;
    return dir;
  }();
  return directory;
}

std::string refine() {
  const std::string& s = cupScene();
  return "hull --calib " + s + "/scene_par.txt --images " + s + " --silhouettes " + s +
         "/masks --max-depth 6 --refine-with-matches --gt-scene " + s + " --json ";
}

TEST(RefineCommand, CarvesWithSiftAndDenseMatchesAndReportsAgainstTheSolid) {
  const std::string points_ply = test::temporaryDirectory() + "/points.ply";
  std::string out, err;
  ASSERT_EQ(test::runProgram(refine() + "--grid-step-px 4 --out-points " + points_ply, &out, &err),
            0)
      << err;
  const nlohmann::json j = nlohmann::json::parse(out);
  const nlohmann::json& points = j["points"];
  EXPECT_EQ(points["pairs"].get<int>(), 22) << out;  // each view with its two nearest
  EXPECT_GT(points["matches_kept"].get<int>(), 100) << out;
  EXPECT_GT(points["dense_matches"].get<int>(), 100) << out;
  EXPECT_GT(points["kept"].get<int>(), 0) << out;
  EXPECT_LE(points["kept"].get<int>(), points["triangulated"].get<int>()) << out;
  EXPECT_EQ(readPly(points_ply).vertices_W.size(), points["kept"].get<size_t>());
  EXPECT_GT(j["carved_volume_m3"].get<double>(), 0.0) << out;
  EXPECT_LE(j["false_carved_fraction"].get<double>(), 0.005) << out;
  EXPECT_LE(j["cavity_filled_m3"]["after"].get<double>(),
            j["cavity_filled_m3"]["before"].get<double>())
      << out;
  EXPECT_GE(j["volume_iou_vs_truth"]["after"].get<double>(),
            j["volume_iou_vs_truth"]["before"].get<double>())
      << out;
  EXPECT_TRUE(j["mesh"]["watertight"].get<bool>()) << out;
  EXPECT_GE(j["reprojection_iou"]["min"].get<double>(), 0.95) << out;
}

TEST(RefineCommand, RefusesBadSettingsByName) {
  std::string out, err;
  const auto refused = [&](const std::string& flags, const std::string& what) {
    EXPECT_EQ(test::runProgram(refine() + flags, &out, &err), 2) << flags;
    EXPECT_NE(err.find(what), std::string::npos) << flags << ": " << err;
  };
  refused("--grid-step-px -1", "grid_step_px");
  refused("--patch-radius-px 0", "patch_radius_px");
  refused("--min-ncc 2", "min_ncc");
  refused("--min-ncc-margin -1", "min_ncc_margin");
  refused("--min-patch-std 2", "min_patch_std");
  refused("--ratio 0", "ratio");
  refused("--filter none", "--filter");
  refused("--max-round-trip-px 0", "max_round_trip_px");
  refused("--match-pairs some", "--match-pairs must be neighbours or all");
  refused("--min-views 0", "min_views");
}

TEST(RefineCommand, PhotoCarvingCarvesAndReportsItsStages) {
  const std::string& s = cupScene();
  const std::string hull = "hull --calib " + s + "/scene_par.txt --silhouettes " + s +
                           "/masks --max-depth 6 --photo-carve --json ";
  std::string out, err;
  EXPECT_EQ(test::runProgram(hull, &out, &err), 2);
  EXPECT_NE(err.find("--photo-carve needs --images"), std::string::npos) << err;
  const std::string no_images = "hull --calib " + s + "/scene_par.txt --silhouettes " + s +
                                "/masks --max-depth 5 --out-color-octree x.ot";
  EXPECT_EQ(test::runProgram(no_images, &out, &err), 2);
  EXPECT_NE(err.find("--out-color-octree needs --images"), std::string::npos) << err;
  EXPECT_EQ(test::runProgram(hull + "--images " + s + " --photo-min-views 0", &out, &err), 2);
  EXPECT_NE(err.find("photo-min-views"), std::string::npos) << err;
  ASSERT_EQ(test::runProgram(hull + "--images " + s + " --photo-image-scale 1 --gt-scene " + s,
                             &out, &err),
            0)
      << err;
  const nlohmann::json j = nlohmann::json::parse(out);
  const nlohmann::json& photo = j["photo_carving"];
  EXPECT_GT(photo["carved_voxels"].get<int>(), 0) << out;
  // Views x neighbours (at most 6 within 75 degrees) x planes.
  const int planes = PhotoCarveConfig{}.photo_depth_planes;
  EXPECT_EQ(photo["sweeps"].get<int>() % planes, 0) << out;
  EXPECT_GT(photo["sweeps"].get<int>(), 20 * 3 * planes) << out;
  EXPECT_LE(photo["sweeps"].get<int>(), 20 * 6 * planes) << out;
  EXPECT_GT(photo["depth_pixels"]["consistent"].get<int>(), 0) << out;
  EXPECT_LE(photo["depth_pixels"]["consistent"].get<int>(),
            photo["depth_pixels"]["swept"].get<int>());
  EXPECT_GT(photo["time_ms"].get<double>(), 0.0);
  EXPECT_GT(photo["carved_volume_m3"].get<double>(), 0.0);
  EXPECT_GT(j["volume_iou_vs_truth"]["after"].get<double>(),
            j["volume_iou_vs_truth"]["before"].get<double>())
      << out;
  EXPECT_LE(j["false_carved_fraction"].get<double>(), 0.005) << out;
  EXPECT_TRUE(j["mesh"]["watertight"].get<bool>()) << out;
}

TEST(RefineCommand, AHeldOutViewMeasuresTheColoursOfTheHullAndOfTheRefinedModel) {
  const std::string& s = cupScene();
  const std::string hull = "hull --calib " + s + "/scene_par.txt --images " + s +
                           " --silhouettes " + s + "/masks --max-depth 6 --json ";
  std::string out, err;
  EXPECT_EQ(test::runProgram(hull + "--holdout-view nothing.png", &out, &err), 2);
  EXPECT_NE(err.find("--holdout-view nothing.png is not one of the views"), std::string::npos)
      << err;
  ASSERT_EQ(test::runProgram(hull + "--photo-carve --holdout-view view_0007.png", &out, &err), 0)
      << err;
  const nlohmann::json j = nlohmann::json::parse(out);
  const nlohmann::json& held = j["holdout_view"];
  EXPECT_EQ(held["name"], "view_0007.png");
  EXPECT_EQ(j["views"].get<int>(), 19) << "the held-out view was carved";
  std::cout << held.dump() << '\n';
  // Measured: 10.3 and 10.0 grey levels, 23.5 and 23.6 dB.
  for (const char* model : {"hull", "refined"}) {
    EXPECT_GT(held[model]["psnr_db"].get<double>(), 20.0) << out;
    EXPECT_LT(held[model]["mae"].get<double>(), 15.0) << out;
  }
  EXPECT_LT(held["refined"]["mae"].get<double>(), held["hull"]["mae"].get<double>()) << out;
}

TEST(RefineCommand, AGroundTruthOfAnotherSceneIsRefusedNamingBoth) {
  const std::string& cup = cupScene();
  const std::string other = test::temporaryDirectory() + "/box";
  std::string out, err;
  ASSERT_EQ(
      test::runProgram("scene --shape box --layout sphere --views 20 --size 320x240 --out " + other,
                       &out, &err),
      0)
      << err;
  const std::string hull = "hull --calib " + cup + "/scene_par.txt --images " + cup +
                           " --silhouettes " + cup + "/masks --max-depth 5 --json --gt-scene ";
  EXPECT_EQ(test::runProgram(hull + other, &out, &err), 1) << out;
  EXPECT_NE(err.find("--gt-scene " + other + " is not the scene of the views of " + cup +
                     "/scene_par.txt: view 'view_0000.png'"),
            std::string::npos)
      << err;
  ASSERT_EQ(test::runProgram(hull + cup, &out, &err), 0) << err;
  EXPECT_GT(nlohmann::json::parse(out)["volume_iou_vs_truth"]["after"].get<double>(), 0.5) << out;
  // The match command: the calibration's cameras against the scene's, and the images' size.
  const std::string pair = "match " + cup + "/view_0000.png " + cup + "/view_0001.png --gt-scene ";
  EXPECT_EQ(test::runProgram(pair + other + " --calib " + cup + "/scene_par.txt", &out, &err), 1);
  EXPECT_NE(err.find("--gt-scene " + other + " is not the scene of the views of " + cup +
                     "/scene_par.txt: view 'view_0000.png'"),
            std::string::npos)
      << err;
  const std::string small = test::temporaryDirectory() + "/small";
  ASSERT_EQ(
      test::runProgram("scene --shape cup --views 2 --size 160x120 --out " + small, &out, &err), 0)
      << err;
  EXPECT_EQ(test::runProgram(pair + small, &out, &err), 1);
  EXPECT_NE(err.find("--gt-scene " + small + " is not the scene of " + cup +
                     "/view_0000.png: its views are 160x120, the image is 320x240"),
            std::string::npos)
      << err;
}

}  // namespace
}  // namespace sift_hull
