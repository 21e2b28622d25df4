// Photo sets as users bring them: RGBA images whose alpha is the silhouette, mask folders named
// with another number width (IDR / DTU), 3-channel masks, a NeRF transforms.json beside them.
#include <gtest/gtest.h>

#include <filesystem>
#include <opencv2/core.hpp>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include "common/test_data.h"
#include "sift_hull/hull/hull_pipeline.h"
#include "sift_hull/io/images.h"
#include "sift_hull/io/nerf.h"
#include "sift_hull/io/view_list.h"
#include "sift_hull/synthetic/scene.h"

namespace sift_hull {
namespace {

SceneConfig smallScene() {
  SceneConfig config;
  config.views = 8;
  config.layout = "sphere";
  config.width_px = 160;
  config.height_px = 120;
  config.background = "textured";
  return config;
}

/// A scene's images as RGBA PNGs (alpha = the true mask) with a transforms.json, in `directory`.
std::vector<RenderedView> writeRgbaNerfScene(const std::string& directory) {
  const SceneConfig config = smallScene();
  const std::vector<RenderedView> views = renderScene(config);
  std::vector<CalibratedView> cameras;
  for (const RenderedView& view : views) {
    cv::Mat rgba;
    cv::cvtColor(view.image, rgba, cv::COLOR_BGR2BGRA);
    cv::insertChannel(view.mask, rgba, 3);
    cv::imwrite(directory + "/" + view.view.name, rgba);
    cameras.push_back(view.view);
  }
  writeNerfTransforms(directory + "/transforms.json", cameras, config.width_px, config.height_px);
  return views;
}

TEST(PhotoSetInputs, AlphaChannelIsTheSilhouetteWithoutMasks) {
  const std::string dir = test::temporaryDirectory();
  const std::vector<RenderedView> truth = writeRgbaNerfScene(dir);
  const HullInput input = loadHullInput(dir + "/transforms.json", dir, "", SilhouetteConfig(), {});
  ASSERT_EQ(input.viewCount(), truth.size());
  for (size_t i = 0; i < truth.size(); ++i) {
    EXPECT_EQ(cv::countNonZero(input.mask(i) != truth[i].mask), 0) << truth[i].view.name;
  }
  // The hull of the json and its alpha masks is the hull of the scene's own calibration.
  const HullResult from_nerf = buildHull(input, HullConfig());
  const HullResult from_scene = buildHull(hullInputOf(truth), HullConfig());
  EXPECT_GT(from_nerf.mesh.faces.size(), 100u);
  EXPECT_EQ(from_nerf.mesh.faces.size(), from_scene.mesh.faces.size());
  EXPECT_LT((from_nerf.box.min_W - from_scene.box.min_W).norm(), 1e-6);
}

TEST(PhotoSetInputs, ConstantAlphaAndPlainImagesFallBackToTheMethod) {
  const std::string dir = test::temporaryDirectory();
  const RenderedView view = renderSceneView(smallScene(), 0);
  cv::Mat opaque;
  cv::cvtColor(view.image, opaque, cv::COLOR_BGR2BGRA);  // alpha 255 everywhere
  cv::imwrite(dir + "/opaque.png", opaque);
  cv::imwrite(dir + "/plain.png", view.image);
  CalibratedView opaque_view = view.view, plain_view = view.view;
  opaque_view.name = "opaque.png";
  plain_view.name = "plain.png";
  const ViewImage a = loadViewImageWithAlpha(dir, opaque_view);
  const ViewImage b = loadViewImageWithAlpha(dir, plain_view);
  EXPECT_TRUE(a.alpha_mask.empty());
  EXPECT_TRUE(b.alpha_mask.empty());
  EXPECT_EQ(cv::norm(a.bgr, view.image, cv::NORM_INF), 0.0);
  EXPECT_EQ(cv::norm(b.bgr, view.image, cv::NORM_INF), 0.0);
}

TEST(PhotoSetInputs, MasksPairByNumberAcrossNameWidthsAndChannels) {
  const std::string dir = test::temporaryDirectory();
  std::filesystem::create_directories(dir + "/image");
  std::filesystem::create_directories(dir + "/mask");
  const SceneConfig config = smallScene();
  const std::vector<RenderedView> views = renderScene(config);
  std::vector<CalibratedView> cameras;
  for (size_t i = 0; i < views.size(); ++i) {
    char image_name[32], mask_name[32];
    std::snprintf(image_name, sizeof(image_name), "%06zu.png", i);
    std::snprintf(mask_name, sizeof(mask_name), "%03zu.png", i);
    cv::imwrite(dir + "/image/" + image_name, views[i].image);
    cv::Mat three;  // DTU's masks are 3-channel
    cv::cvtColor(views[i].mask, three, cv::COLOR_GRAY2BGR);
    cv::imwrite(dir + "/mask/" + mask_name, three);
    cameras.push_back(views[i].view);
    cameras.back().name = image_name;
  }
  writeNerfTransforms(dir + "/image/transforms.json", cameras, config.width_px, config.height_px);
  EXPECT_EQ(maskPath(dir + "/mask", "000003.png"), dir + "/mask/003.png");
  EXPECT_EQ(maskPath(dir + "/mask", "3.jpg"), dir + "/mask/003.png");
  EXPECT_EQ(maskPath(dir + "/mask", "view_a.png"), dir + "/mask/view_a.png");
  const HullInput input =
      loadHullInput(dir + "/image/transforms.json", dir + "/image", dir + "/mask", {}, {});
  ASSERT_EQ(input.viewCount(), views.size());
  for (size_t i = 0; i < views.size(); ++i) {
    EXPECT_EQ(cv::countNonZero(input.mask(i) != views[i].mask), 0) << i;
  }
  // Two files of the same number are ambiguous: the error names the image's own name.
  cv::imwrite(dir + "/mask/3.png", views[3].mask);
  EXPECT_EQ(maskPath(dir + "/mask", "000003.png"), dir + "/mask/000003.png");
  try {
    loadHullInput(dir + "/image/transforms.json", dir + "/image", dir + "/mask", {}, {});
    ADD_FAILURE() << "an ambiguous mask was taken";
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find("mask/000003.png: mask missing"), std::string::npos)
        << e.what();
  }
}

}  // namespace
}  // namespace sift_hull

namespace sift_hull {
namespace {

TEST(PhotoSetInputs, SceneWritesTheSameCamerasInEveryFormat) {
  const std::string dir = test::temporaryDirectory();
  SceneConfig config = smallScene();
  writeScene(dir, config, renderScene(config));
  const std::vector<CalibratedView> par = readCalibration(dir + "/scene_par.txt");
  const std::vector<CalibratedView> nerf = readCalibration(dir + "/transforms.json");
  const std::vector<CalibratedView> idr = readCalibrationWithImages(dir + "/cameras.npz", dir);
  ASSERT_EQ(nerf.size(), par.size());
  ASSERT_EQ(idr.size(), par.size());
  for (size_t i = 0; i < par.size(); ++i) {
    EXPECT_EQ(nerf[i].name, par[i].name);
    EXPECT_EQ(idr[i].name, par[i].name);
    for (const Eigen::Vector3d& X :
         {Eigen::Vector3d(0.3, -0.2, 0.1), Eigen::Vector3d(-0.4, 0.5, 0.2)}) {
      EXPECT_LT((nerf[i].camera.project(X) - par[i].camera.project(X)).norm(), 1e-6);
      EXPECT_LT((idr[i].camera.project(X) - par[i].camera.project(X)).norm(), 1e-6);
    }
  }
}

}  // namespace
}  // namespace sift_hull
