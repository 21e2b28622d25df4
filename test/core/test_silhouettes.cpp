// Silhouettes from images: the background-model method against the renderer's exact masks on
// black, dark blue and textured backgrounds, and on the Middlebury rings by the hull they give.
#include <gtest/gtest.h>

#include <cmath>
#include <iostream>
#include <nlohmann/json.hpp>
#include <opencv2/imgproc.hpp>
#include <stdexcept>
#include <string>
#include <vector>

#include "common/test_data.h"
#include "sift_hull/eval/hull_evaluation.h"
#include "sift_hull/hull/hull_pipeline.h"
#include "sift_hull/hull/silhouette.h"
#include "sift_hull/io/view_list.h"
#include "sift_hull/synthetic/scene.h"

namespace sift_hull {
namespace {

/// The background model, which the default method (auto) takes for one image alone.
SilhouetteConfig backgroundMethod() {
  SilhouetteConfig config;
  config.silhouette_method = "background";
  return config;
}

SilhouetteConfig thresholdMethod() {
  SilhouetteConfig config;
  config.silhouette_method = "threshold";
  return config;
}

struct MaskScores {
  double smallest = 1.0, mean = 0.0;
};

/// The mask IoU of the method against the exact masks over the 8 views of a 320x240 scene on
/// `background`.
MaskScores maskScores(const std::string& background, const SilhouetteConfig& method) {
  SceneConfig config;
  config.views = 8;
  config.width_px = 320;
  config.height_px = 240;
  config.background = background;
  MaskScores scores;
  for (const RenderedView& view : renderScene(config)) {
    const double iou = maskIoU(silhouetteFromImage(view.image, method), view.mask);
    scores.smallest = std::min(scores.smallest, iou);
    scores.mean += iou / config.views;
  }
  std::cout << background << " background, " << method.silhouette_method << ": mask IoU smallest "
            << scores.smallest << ", mean " << scores.mean << "\n";
  return scores;
}

double smallestIoU(const std::string& background, const SilhouetteConfig& method) {
  return maskScores(background, method).smallest;
}

TEST(BackgroundSilhouettes, ComeCloseToTheExactMasksOnEveryBackground) {
  // Measured (8 views of 320x240), smallest / mean: black 0.973 / 0.991, blue 0.973 / 0.991,
  // textured 0.971 / 0.986. What is lost is mostly where the object lets the background through
  // (the hole of the sculpture's ring), which the filling of holes closes.
  for (const char* background : {"black", "blue", "textured"}) {
    const MaskScores scores = maskScores(background, backgroundMethod());
    EXPECT_GE(scores.smallest, 0.96) << background;
    EXPECT_GE(scores.mean, 0.98) << background;
  }
}

TEST(BackgroundSilhouettes, GiveATexturedSceneItsHull) {
  const std::string dir = test::temporaryDirectory();
  std::string out, err;
  ASSERT_EQ(
      test::runProgram("scene --out " + dir + " --views 8 --size 320x240 --background textured",
                       &out, &err),
      0)
      << err;
  ASSERT_EQ(test::runProgram(
                "hull --calib " + dir + "/scene_par.txt --images " + dir + " --max-depth 7 --json",
                &out, &err),
            0)
      << err;
  const nlohmann::json result = nlohmann::json::parse(out);
  EXPECT_GT(result["reprojection_iou"]["mean"].get<double>(), 0.97) << out;
  EXPECT_TRUE(result["warnings"].empty()) << out;
}

TEST(BackgroundSilhouettes, TheGreyThresholdFailsOnDarkBlueWhereTheBackgroundModelDoesNot) {
  // Measured: 0.139, the whole image taken for the object.
  EXPECT_LT(smallestIoU("blue", thresholdMethod()), 0.2);
}

/// The mean reprojection IoU of the hull of a Middlebury ring at depth 8 by `method` (NaN when the
/// data set is absent).
double ringIoU(const std::string& directory, const std::string& calibration,
               const std::string& view_list, const SilhouetteConfig& method) {
  const std::string dir = test::dataSet(directory);
  if (dir.empty()) return NAN;
  const std::vector<std::string> views =
      view_list.empty() ? std::vector<std::string>{} : readViewList(dir + "/" + view_list);
  HullConfig config;
  config.max_depth = 8;
  const HullResult result =
      buildHull(loadHullInput(dir + "/" + calibration, dir, "", method, views), config);
  const double iou = reprojectionIoU(result.mesh, result.hull.views()).mean;
  std::cout << directory << ", " << method.silhouette_method << ": mean reprojection IoU " << iou
            << "\n";
  return iou;
}

TEST(BackgroundSilhouettes, GiveTheMiddleburyRingsTheirHullWithoutAThreshold) {
  // Measured at depth 8 (sift_hull hull ... with the default method, auto, which takes the
  // background method's silhouettes here): dino (good list) 0.988, temple (all 16) 0.982; the
  // threshold recipe at its default gives 0.989 and 0.958.
  const double dino = ringIoU("middlebury_mvs_dinoSparseRing", "dinoSR_par.txt",
                              "dinoSR_good_silhouette_images.txt", SilhouetteConfig());
  const double temple =
      ringIoU("middlebury_mvs_templeSparseRing", "templeSR_par.txt", "", SilhouetteConfig());
  if (std::isnan(dino) && std::isnan(temple)) GTEST_SKIP() << "no Middlebury ring found";
  if (!std::isnan(dino)) {
    EXPECT_GE(dino, 0.985);
  }
  if (!std::isnan(temple)) {
    EXPECT_GE(temple, 0.98);
  }
}

TEST(SilhouetteWarnings, NameEmptyFullAndBorderTouchingSilhouettes) {
  const cv::Size size(40, 30);
  cv::Mat good(size, CV_8UC1, cv::Scalar(0)), empty = good.clone(), full(size, CV_8UC1, 255);
  cv::rectangle(good, cv::Rect(10, 5, 20, 20), 255, cv::FILLED);
  cv::Mat frame = good.clone();  // touches every border, covers under 90 %
  cv::rectangle(frame, cv::Rect(0, 0, 40, 30), 255, 1);
  const std::vector<std::string> warnings =
      silhouetteWarnings({"good", "empty", "full", "frame"}, {good, empty, full, frame});
  ASSERT_EQ(warnings.size(), 3u);
  EXPECT_EQ(warnings[0].rfind("empty: the silhouette is empty", 0), 0u) << warnings[0];
  EXPECT_EQ(warnings[1].rfind("full: the silhouette covers 100 %", 0), 0u) << warnings[1];
  EXPECT_EQ(warnings[2].rfind("frame: the silhouette touches all four", 0), 0u) << warnings[2];
  EXPECT_THROW(silhouetteWarnings({"a"}, {}), std::invalid_argument);
}

TEST(SilhouetteWarnings, NameTheViewFarBelowTheOthers) {
  const std::vector<std::string> names = {"a", "b", "c", "d"};
  EXPECT_TRUE(disagreeingViewWarnings(names, {0.99, 0.98, 0.985, 0.95}).empty());
  const std::vector<std::string> warnings =
      disagreeingViewWarnings(names, {0.99, 0.62, 0.985, 0.97});
  ASSERT_EQ(warnings.size(), 1u);
  EXPECT_EQ(warnings[0].rfind("b: the hull reprojects onto its silhouette with IoU 0.62", 0), 0u)
      << warnings[0];
  // On the blue background the grey threshold's silhouettes are all suspect.
  SceneConfig config;
  config.views = 3;
  config.width_px = 160;
  config.height_px = 120;
  config.background = "blue";
  std::vector<std::string> scene_names;
  std::vector<cv::Mat> masks;
  for (const RenderedView& view : renderScene(config)) {
    scene_names.push_back(view.view.name);
    masks.push_back(silhouetteFromImage(view.image, thresholdMethod()));
  }
  EXPECT_EQ(silhouetteWarnings(scene_names, masks).size(), 3u);
}

TEST(SilhouetteWarnings, TheHullCommandNamesTheSuspectViews) {
  const std::string dir = test::temporaryDirectory();
  std::string out, err;
  ASSERT_EQ(test::runProgram("scene --out " + dir + " --views 6 --size 160x120 --background blue",
                             &out, &err),
            0)
      << err;
  // The grey threshold takes every whole image for the object: each view is named, then no box
  // can be bounded.
  EXPECT_EQ(test::runProgram("hull --calib " + dir + "/scene_par.txt --images " + dir +
                                 " --max-depth 6 --threshold 0.19 --allow-poor --json",
                             &out, &err),
            1);
  EXPECT_NE(err.find("view_0003.png: the silhouette covers 100 %"), std::string::npos) << err;
  EXPECT_NE(err.find("bounded silhouette side"), std::string::npos) << err;
  // The background model, the default, needs no threshold there, and warns of nothing.
  ASSERT_EQ(test::runProgram(
                "hull --calib " + dir + "/scene_par.txt --images " + dir + " --max-depth 6 --json",
                &out, &err),
            0)
      << err;
  EXPECT_TRUE(nlohmann::json::parse(out).at("warnings").empty()) << out;
}

TEST(BackgroundSilhouettes, UnknownMethodsAndBadImagesAreRefused) {
  SilhouetteConfig config;
  config.silhouette_method = "magic";
  EXPECT_THROW(validate(config), std::invalid_argument);
  EXPECT_THROW(backgroundDistance(cv::Mat()), std::invalid_argument);
  EXPECT_THROW(backgroundDistance(cv::Mat(10, 10, CV_32FC3)), std::invalid_argument);
  // A uniform image is all background: nothing inside.
  const cv::Mat grey(40, 50, CV_8UC3, cv::Scalar(90, 120, 30));
  EXPECT_EQ(cv::countNonZero(silhouetteFromImage(grey, backgroundMethod())), 0);
}

}  // namespace
}  // namespace sift_hull
