// Photographs without masks read and segmented at a reduction (photographReduction,
// loadReducedViewImage, loadReducedPhotoHullInput): the silhouettes against the renderer's exact
// masks and against segmentation at full resolution.
#include <gtest/gtest.h>

#include <atomic>
#include <cstdio>
#include <filesystem>
#include <nlohmann/json.hpp>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include "common/test_data.h"
#include "sift_hull/eval/hull_evaluation.h"
#include "sift_hull/io/calibration.h"
#include "sift_hull/io/images.h"
#include "sift_hull/io/reduced_images.h"
#include "sift_hull/io/view_list.h"
#include "sift_hull/synthetic/scene.h"

namespace sift_hull {
namespace {

TEST(PhotographReduction, FollowsTheFinestVoxelAndKeepsSmallImagesWhole) {
  const cv::Size twelve_mp(4000, 3000);
  // The finest voxel spans longest / 2^(depth + 1) pixels when the box spans half the image.
  EXPECT_EQ(photographReduction(twelve_mp, 7, 400, 8), 8);   // 15.6 px
  EXPECT_EQ(photographReduction(twelve_mp, 8, 400, 8), 4);   // 7.8 px
  EXPECT_EQ(photographReduction(twelve_mp, 9, 400, 8), 2);   // 3.9 px
  EXPECT_EQ(photographReduction(twelve_mp, 10, 400, 8), 1);  // 1.95 px
  EXPECT_EQ(photographReduction(twelve_mp, 7, 400, 2), 2);   // at most --max-input-reduction
  EXPECT_EQ(photographReduction(twelve_mp, 7, 400, 1), 1);
  // The views method's working size is kept: 4000 / 1500 = 2.7.
  EXPECT_EQ(photographReduction(twelve_mp, 7, 1500, 8), 2);
  // Under 2 MP, as for mask files: Middlebury's 640x480 and 1600x1200 stay whole.
  EXPECT_EQ(photographReduction(cv::Size(640, 480), 5, 400, 8), 1);
  EXPECT_EQ(photographReduction(cv::Size(1600, 1200), 5, 400, 8), 1);
  EXPECT_EQ(photographReduction(cv::Size(), 8, 400, 8), 1);
  EXPECT_THROW(photographReduction(twelve_mp, 8, 400, 3), std::invalid_argument);
}

TEST(ReducedViewImage, JpegDecodesAtScaleAndPngWithAlphaReducesItsMask) {
  const std::string dir = test::temporaryDirectory();
  const RenderedView rendered = renderView(
      Shape::byName("sculpture"), sceneCameras(SceneConfig(), Shape::byName("sculpture"))[0],
      cv::Size(640, 480), 1, "textured");
  CalibratedView view;
  view.name = "photo.jpg";
  ASSERT_TRUE(cv::imwrite(dir + "/photo.jpg", rendered.image, {cv::IMWRITE_JPEG_QUALITY, 95}));
  cv::Size full;
  const ViewImage jpeg = loadReducedViewImage(dir, view, 4, &full);
  EXPECT_EQ(full, cv::Size(640, 480));
  ASSERT_EQ(jpeg.bgr.size(), cv::Size(160, 120));
  EXPECT_TRUE(jpeg.alpha_mask.empty());
  // libjpeg's scaled decoding against the full image reduced by area: the same picture.
  const cv::Mat by_area = reduceImage(cv::imread(dir + "/photo.jpg"), 4);
  EXPECT_LT(cv::norm(jpeg.bgr, by_area, cv::NORM_L1) / by_area.total() / 3.0, 3.0);
  // A PNG with an alpha channel: the image and its mask reduced by area.
  cv::Mat bgra;
  cv::cvtColor(rendered.image, bgra, cv::COLOR_BGR2BGRA);
  cv::Mat channels[4];
  cv::split(bgra, channels);
  channels[3] = rendered.mask;
  cv::merge(channels, 4, bgra);
  view.name = "photo.png";
  ASSERT_TRUE(cv::imwrite(dir + "/photo.png", bgra));
  const ViewImage png = loadReducedViewImage(dir, view, 2, &full);
  EXPECT_EQ(full, cv::Size(640, 480));
  ASSERT_EQ(png.bgr.size(), cv::Size(320, 240));
  ASSERT_EQ(png.alpha_mask.size(), cv::Size(320, 240));
  EXPECT_EQ(cv::countNonZero(png.alpha_mask != reduceMask(rendered.mask, 2)), 0);
  // A calibration of another size is refused, naming both sizes.
  view.name = "photo.jpg";
  view.width_px = 800;
  view.height_px = 600;
  try {
    loadReducedViewImage(dir, view, 4, &full);
    ADD_FAILURE() << "a size other than the calibration's was accepted";
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find("800x600"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("640x480"), std::string::npos) << e.what();
  }
}

/// 10 views of 1800x1200 (2.2 MP) of the sculpture on a floor, as JPEG photographs with a par
/// file in `dir`; the exact masks.
std::vector<cv::Mat> writePhotographs(const std::string& dir) {
  SceneConfig scene;
  scene.views = 10;
  scene.layout = "sphere";
  scene.support = "floor";
  scene.width_px = 1800;
  scene.height_px = 1200;
  std::vector<CalibratedView> views = sceneCameras(scene, Shape::byName(scene.shape));
  std::vector<cv::Mat> masks;
  for (size_t i = 0; i < views.size(); ++i) {
    const RenderedView rendered = renderSceneView(scene, i);
    views[i].name = std::filesystem::path(views[i].name).stem().string() + ".jpg";
    EXPECT_TRUE(
        cv::imwrite(dir + "/" + views[i].name, rendered.image, {cv::IMWRITE_JPEG_QUALITY, 92}));
    masks.push_back(rendered.mask);
  }
  writeMiddleburyPar(dir + "/scene_par.txt", views);
  return masks;
}

class ReducedPhotoHullInput : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    dir_ = new std::string(test::temporaryDirectory());
    truth_ = new std::vector<cv::Mat>(writePhotographs(*dir_));
  }
  static void TearDownTestSuite() {
    delete dir_;
    delete truth_;
  }
  static HullConfig depth7() {
    HullConfig config;
    config.max_depth = 7;  // 1800 / 2^8 = 7.0 px: read at 1/4
    return config;
  }
  static double meanIoU(const HullInput& input, int reduction) {
    double sum = 0.0;
    for (size_t i = 0; i < truth_->size(); ++i) {
      sum += maskIoU(input.mask(i), reduceMask((*truth_)[i], reduction));
    }
    return sum / truth_->size();
  }
  static std::string* dir_;
  static std::vector<cv::Mat>* truth_;
};
std::string* ReducedPhotoHullInput::dir_ = nullptr;
std::vector<cv::Mat>* ReducedPhotoHullInput::truth_ = nullptr;

TEST_F(ReducedPhotoHullInput, ReadsAndSegmentsEachViewAtTheReduction) {
  const std::string par = *dir_ + "/scene_par.txt";
  std::atomic<size_t> most_read{0};
  ViewSilhouettes found;
  const HullInput reduced = loadReducedPhotoHullInput(
      par, *dir_, {}, SilhouetteConfig(), depth7(), 8, &found, [&](size_t read, size_t total) {
        EXPECT_EQ(total, truth_->size());
        size_t seen = most_read;
        while (read > seen && !most_read.compare_exchange_weak(seen, read)) {
        }
      });
  EXPECT_EQ(most_read, truth_->size());
  EXPECT_EQ(found.method, "views");
  const std::vector<CalibratedView> views = readCalibration(par);
  ASSERT_EQ(reduced.viewCount(), truth_->size());
  for (size_t i = 0; i < truth_->size(); ++i) {
    EXPECT_EQ(reduced.reduction(i), 4);
    EXPECT_EQ(reduced.image_sizes[i], cv::Size(1800, 1200));
    EXPECT_EQ(reduced.mask(i).size(), cv::Size(450, 300));
    EXPECT_TRUE(reduced.cameras[i].K().isApprox(views[i].camera.reduced(4).K()));
  }
  EXPECT_GT(meanIoU(reduced, 4), 0.96);
  // The hull command reads them so and reports the reduction.
  std::string stdout_text, stderr_text;
  ASSERT_EQ(test::runProgram("hull --calib " + par + " --images " + *dir_ + " --max-depth 7 --json",
                             &stdout_text, &stderr_text),
            0)
      << stderr_text;
  const nlohmann::json result = nlohmann::json::parse(stdout_text);
  EXPECT_EQ(result["input_reduction"]["max"], 4);
  EXPECT_EQ(result["input_reduction"]["image_size"], nlohmann::json({1800, 1200}));
  EXPECT_GT(result["reprojection_iou"]["mean"].get<double>(), 0.95);
}

TEST_F(ReducedPhotoHullInput, SegmentsAsWellAsAtFullResolution) {
  const std::string par = *dir_ + "/scene_par.txt";
  const HullInput reduced =
      loadReducedPhotoHullInput(par, *dir_, {}, SilhouetteConfig(), depth7(), 8);
  const HullInput whole =
      loadReducedPhotoHullInput(par, *dir_, {}, SilhouetteConfig(), depth7(), 1);
  EXPECT_EQ(whole.reduction(0), 1);
  EXPECT_EQ(whole.mask(0).size(), cv::Size(1800, 1200));
  const double reduced_iou = meanIoU(reduced, 4), whole_iou = meanIoU(whole, 1);
  std::printf("mask IoU against the exact masks: %.4f at 1/4, %.4f at full resolution\n",
              reduced_iou, whole_iou);
  EXPECT_GT(reduced_iou, whole_iou - 0.01);
}

}  // namespace
}  // namespace sift_hull
