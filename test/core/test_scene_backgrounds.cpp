// The renderer's backgrounds (SceneConfig::background): the object and its exact silhouette stay
// as on black, only the rays that miss it change colour.
#include <gtest/gtest.h>

#include <opencv2/imgproc.hpp>
#include <stdexcept>
#include <string>

#include "common/test_data.h"
#include "sift_hull/hull/silhouette.h"
#include "sift_hull/synthetic/scene.h"

namespace sift_hull {
namespace {

SceneConfig smallScene(const std::string& background) {
  SceneConfig config;
  config.views = 2;
  config.width_px = 160;
  config.height_px = 120;
  config.background = background;
  return config;
}

/// The share of pixels of `mask` that are set.
double coverage(const cv::Mat& mask) {
  return static_cast<double>(cv::countNonZero(mask)) / static_cast<double>(mask.total());
}

TEST(SceneBackground, OnlyThePixelsOutsideTheObjectChange) {
  const RenderedView black = renderSceneView(smallScene("black"), 1);
  for (const char* background : {"blue", "textured"}) {
    const RenderedView view = renderSceneView(smallScene(background), 1);
    EXPECT_EQ(cv::countNonZero(view.mask != black.mask), 0) << background;
    cv::Mat difference;
    cv::absdiff(view.image, black.image, difference);
    cv::Mat changed;
    cv::cvtColor(difference, changed, cv::COLOR_BGR2GRAY);
    changed = changed > 0;
    EXPECT_EQ(cv::countNonZero(changed & black.mask), 0) << background << ": the object changed";
    cv::Mat outside;
    cv::bitwise_not(black.mask, outside);
    EXPECT_EQ(cv::countNonZero(changed), cv::countNonZero(outside))
        << background << ": a background pixel stayed black";
  }
}

TEST(SceneBackground, BlueDefeatsTheGreyThresholdAndTexturedIsColourful) {
  const RenderedView blue = renderSceneView(smallScene("blue"), 0);
  const cv::Mat exact_black = renderSceneView(smallScene("black"), 0).mask;
  // The Middlebury recipe (grey > 0.19) takes the dark blue for the object: nearly all the image.
  EXPECT_LT(coverage(exact_black), 0.5);
  SilhouetteConfig grey;
  grey.silhouette_method = "threshold";
  EXPECT_GT(coverage(silhouetteFromImage(blue.image, grey)), 0.97);

  const RenderedView textured = renderSceneView(smallScene("textured"), 0);
  cv::Mat outside;
  cv::bitwise_not(textured.mask, outside);
  cv::Scalar mean, stddev;
  cv::meanStdDev(textured.image, mean, stddev, outside);
  for (int c = 0; c < 3; ++c) {
    EXPECT_GT(stddev[c], 20.0) << "channel " << c << " of the textured background is flat";
    EXPECT_GT(mean[c], 40.0) << "channel " << c;
  }
}

TEST(SceneBackground, IsWrittenReadBackAndCheckedByName) {
  const std::string dir = test::temporaryDirectory();
  const SceneConfig config = smallScene("textured");
  writeScene(dir, config, renderScene(config));
  EXPECT_EQ(readScene(dir).config.background, "textured");
  SceneConfig bad = smallScene("pink");
  EXPECT_THROW(validate(bad), std::invalid_argument);
  std::string out, err;
  EXPECT_EQ(test::runProgram("scene --out " + dir + "/x --background pink", &out, &err), 2);
  EXPECT_NE(err.find("background must be"), std::string::npos) << err;
}

}  // namespace
}  // namespace sift_hull
