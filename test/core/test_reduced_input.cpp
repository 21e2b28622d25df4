// Reduced loading: image sizes from file headers, masks decoded at 1/2, 1/4 and 1/8 (JPEG's own
// scaled decoding, others reduced by area), cameras reduced alike, and the hull of a reduced
// view set against the full-resolution one.
#include <gtest/gtest.h>

#include <atomic>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include "common/test_data.h"
#include "sift_hull/eval/hull_evaluation.h"
#include "sift_hull/hull/hull_pipeline.h"
#include "sift_hull/io/calibration.h"
#include "sift_hull/io/images.h"
#include "sift_hull/io/reduced_images.h"
#include "sift_hull/io/view_list.h"
#include "sift_hull/synthetic/mask_render.h"
#include "sift_hull/synthetic/scene.h"

namespace sift_hull {
namespace {

/// A disc mask of 255 on 0.
cv::Mat discMask(cv::Size size) {
  cv::Mat mask = cv::Mat::zeros(size, CV_8UC1);
  cv::circle(mask, cv::Point(size.width / 2, size.height / 2), size.height / 3, 255, cv::FILLED);
  return mask;
}

TEST(ImageFileSize, ReadsPngAndJpegHeadersAndDecodesOtherFormats) {
  const std::string dir = test::temporaryDirectory();
  const cv::Mat mask = discMask(cv::Size(333, 171));
  for (const std::string name : {"a.png", "a.jpg", "a.JPEG", "a.bmp", "a.tif"}) {
    ASSERT_TRUE(cv::imwrite(dir + "/" + name, mask)) << name;
    EXPECT_EQ(imageFileSize(dir + "/" + name), cv::Size(333, 171)) << name;
  }
  // A PNG named .jpg and a JPEG named .png: the header says what they are.
  std::filesystem::copy_file(dir + "/a.png", dir + "/png.jpg");
  std::filesystem::copy_file(dir + "/a.jpg", dir + "/jpeg.png");
  EXPECT_EQ(imageFileSize(dir + "/png.jpg"), cv::Size(333, 171));
  EXPECT_EQ(imageFileSize(dir + "/jpeg.png"), cv::Size(333, 171));
  // A JPEG whose EXIF orientation (6: turned 90 degrees) cv::imread applies: the decoded size.
  {
    std::ifstream in(dir + "/a.jpg", std::ios::binary);
    const std::string jpeg((std::istreambuf_iterator<char>(in)), {});
    const std::string tiff("II*\0\x08\0\0\0\x01\0\x12\x01\x03\0\x01\0\0\0\x06\0\0\0\0\0\0\0", 26);
    const std::string app1 = std::string("\xFF\xE1\0\x22", 4) + std::string("Exif\0\0", 6) + tiff;
    std::ofstream(dir + "/turned.jpg", std::ios::binary)
        << jpeg.substr(0, 2) + app1 + jpeg.substr(2);
    ASSERT_EQ(cv::imread(dir + "/turned.jpg").size(), cv::Size(171, 333));
    EXPECT_EQ(imageFileSize(dir + "/turned.jpg"), cv::Size(171, 333));
  }
  EXPECT_THROW(imageFileSize(dir + "/missing.png"), std::runtime_error);
  std::ofstream(dir + "/empty.jpg") << "";
  EXPECT_THROW(imageFileSize(dir + "/empty.jpg"), std::runtime_error);
  std::ofstream(dir + "/truncated.jpg") << "\xFF\xD8\xFF\xE0";
  EXPECT_THROW(imageFileSize(dir + "/truncated.jpg"), std::runtime_error);
}

TEST(ReducedMasks, JpegAndPngReduceToTheAreaOfTheFullMask) {
  const std::string dir = test::temporaryDirectory();
  const cv::Size size(1001, 750);  // odd sides: the last reduced row and column are partial
  const cv::Mat mask = discMask(size);
  ASSERT_TRUE(cv::imwrite(dir + "/m.jpg", mask, {cv::IMWRITE_JPEG_QUALITY, 95}));
  ASSERT_TRUE(cv::imwrite(dir + "/m.png", mask));
  cv::Mat ones;
  cv::threshold(mask, ones, 0, 1, cv::THRESH_BINARY);  // a 0/1 mask, as some tools write them
  ASSERT_TRUE(cv::imwrite(dir + "/ones.png", ones));
  for (int reduction : {1, 2, 4, 8}) {
    const cv::Mat expected = reduceMask(mask, reduction);
    EXPECT_EQ(expected.size(), reducedSize(size, reduction));
    for (const std::string name : {"m.jpg", "m.png", "ones.png"}) {
      const cv::Mat reduced = readMaskReduced(dir + "/" + name, reduction);
      ASSERT_EQ(reduced.size(), reducedSize(size, reduction)) << name << " at " << reduction;
      ASSERT_EQ(reduced.type(), CV_8UC1);
      const double differing = cv::countNonZero((reduced != 0) != (expected != 0));
      // The disc's outline only: JPEG's scaled decoding against area averaging.
      EXPECT_LE(differing, 0.02 * cv::countNonZero(expected)) << name << " at " << reduction;
      // Its area within a reduced pixel's band along the outline.
      const double area = cv::countNonZero(reduced) * reduction * reduction;
      EXPECT_NEAR(area, cv::countNonZero(mask), 2.0 * M_PI * size.height / 3 * reduction)
          << name << " at " << reduction;
    }
  }
  EXPECT_THROW(readMaskReduced(dir + "/m.jpg", 3), std::invalid_argument);
  EXPECT_THROW(readMaskReduced(dir + "/missing.jpg", 2), std::runtime_error);
}

TEST(ReducedCamera, ProjectsWhereTheReducedImageHoldsThePoint) {
  Eigen::Matrix3d K;
  K << 1200.0, 0.5, 801.3, 0.0, 1190.0, 602.7, 0.0, 0.0, 1.0;
  const Eigen::Matrix3d R =
      Eigen::AngleAxisd(0.3, Eigen::Vector3d(0.2, 1.0, 0.1).normalized()).toRotationMatrix();
  const PinholeCamera camera =
      PinholeCamera(K, R, Eigen::Vector3d(0.1, -0.2, 4.0)).withDistortion({-0.1, 0.02, 0, 0, 0});
  const Eigen::Vector3d X(0.3, -0.2, 0.5);
  for (int r : {1, 2, 4, 8}) {
    const PinholeCamera reduced = camera.reduced(r);
    const Eigen::Vector2d u = camera.project(X), u_r = reduced.project(X);
    // Reduced pixel u' covers full pixels r u' .. r u' + r - 1: its centre is r u' + (r - 1) / 2.
    EXPECT_LT((r * u_r + Eigen::Vector2d::Constant(0.5 * (r - 1)) - u).norm(), 1e-9) << r;
    EXPECT_LT((reduced.centre() - camera.centre()).norm(), 1e-12);
  }
  EXPECT_THROW(camera.reduced(0), std::invalid_argument);
  // A mirrored world's camera stays mirrored.
  EXPECT_TRUE(camera.negated().reduced(2).improper());
}

/// 24 views of 2400x1800 of the sculpture: JPEG masks and a par file in `dir`; the scene's cameras.
std::vector<CalibratedView> writeJpegMasks(const std::string& dir) {
  SceneConfig scene;
  scene.views = 24;
  scene.layout = "sphere";
  scene.width_px = 2400;
  scene.height_px = 1800;
  const Shape shape = Shape::byName(scene.shape);
  std::vector<CalibratedView> views = sceneCameras(scene, shape);
  for (CalibratedView& view : views) {
    view.name = std::filesystem::path(view.name).stem().string() + ".jpg";
    const cv::Mat mask = renderMask(shape, view.camera, cv::Size(scene.width_px, scene.height_px));
    EXPECT_TRUE(cv::imwrite(dir + "/" + view.name, mask, {cv::IMWRITE_JPEG_QUALITY, 95}));
  }
  writeMiddleburyPar(dir + "/scene_par.txt", views);
  return views;
}

class ReducedViewSet : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    dir_ = new std::string(test::temporaryDirectory());
    writeJpegMasks(*dir_);
  }
  static void TearDownTestSuite() { delete dir_; }
  static HullConfig depth(int levels) {
    HullConfig config;
    config.max_depth = levels;
    return config;
  }
  static std::string* dir_;
};
std::string* ReducedViewSet::dir_ = nullptr;

TEST_F(ReducedViewSet, DecodesEachViewAtItsVoxelsFootprintAndKeepsTheHull) {
  const std::string par = *dir_ + "/scene_par.txt";
  const HullInput full = loadRunLengthHullInput(par, *dir_, *dir_, SilhouetteConfig(), {});
  const HullInput reduced = loadReducedHullInput(par, *dir_, *dir_, {}, depth(7), {}, 8);
  ASSERT_EQ(reduced.viewCount(), full.viewCount());
  ASSERT_EQ(reduced.image_sizes.size(), full.viewCount());
  const HullResult full_hull = buildHull(full, depth(7));
  for (size_t i = 0; i < reduced.viewCount(); ++i) {
    const int r = reduced.reduction(i);
    // At depth 7 a finest voxel covers 4 to 8 pixels of these views: reduced by 4.
    EXPECT_EQ(r, 4) << reduced.names[i];
    EXPECT_EQ(reduced.image_sizes[i], cv::Size(2400, 1800));
    EXPECT_EQ(reduced.run_length_masks[i].size(), reducedSize(cv::Size(2400, 1800), r));
    EXPECT_LT((reduced.cameras[i].K() - full.cameras[i].reduced(r).K()).norm(), 1e-12);
    // No finer than the distance maps the full-resolution hull chose.
    EXPECT_LE(r, full_hull.hull.views()[i].distanceReduction());
  }
  std::vector<std::string> stages;
  const HullResult reduced_hull =
      buildHull(reduced, depth(7), {}, [&](const std::string& stage) { stages.push_back(stage); });
  EXPECT_EQ(stages, std::vector<std::string>({"distance maps", "octree", "mesh"}));
  const ReprojectionIoU full_iou = reprojectionIoU(full_hull.mesh, full_hull.hull.views(), 2);
  const ReprojectionIoU reduced_iou =
      reprojectionIoU(reduced_hull.mesh, reduced_hull.hull.views(), 2);
  std::cout << "reprojection IoU mean, full " << full_iou.mean << ", reduced " << reduced_iou.mean
            << "; box edge " << full_hull.box.size().maxCoeff() << " and "
            << reduced_hull.box.size().maxCoeff() << '\n';
  EXPECT_NEAR(reduced_iou.mean, full_iou.mean, 0.002);
  // The IoU sampled at every k-th pixel (as `hull` does for views over 2^20 pixels), and drawn
  // with half the faces of the watertight mesh: the same within a thousandth.
  ASSERT_TRUE(reduced_hull.mesh_check.watertight);
  const ReprojectionIoU sampled =
      reprojectionIoU(reduced_hull.mesh, reduced_hull.hull.views(), 2, 40000, true);
  EXPECT_EQ(sampled.sample_step_px, 3);  // 600x450 views: 200x150 samples
  EXPECT_NEAR(sampled.mean, reduced_iou.mean, 0.001);
  const ReprojectionIoU half =
      reprojectionIoU(reduced_hull.mesh, reduced_hull.hull.views(), 2, 0, true);
  EXPECT_NEAR(half.mean, reduced_iou.mean, 1e-4);
  EXPECT_LT((reduced_hull.box.min_W - full_hull.box.min_W).norm(),
            0.01 * full_hull.box.size().maxCoeff());
  // A finer octree asks for finer masks; max_reduction 1 is the full-resolution input.
  EXPECT_EQ(loadReducedHullInput(par, *dir_, *dir_, {}, depth(9), {}, 8).reduction(0), 1);
  // Each view reported once as it is read, from the reading threads.
  std::atomic<size_t> reported{0}, largest{0};
  const HullInput by_two =
      loadReducedHullInput(par, *dir_, *dir_, {}, depth(7), {}, 2, [&](size_t read, size_t total) {
        ++reported;
        EXPECT_EQ(total, 24u);
        size_t seen = largest;
        while (read > seen && !largest.compare_exchange_weak(seen, read)) {
        }
      });
  EXPECT_EQ(by_two.reduction(0), 2);
  EXPECT_EQ(reported, 24u);
  EXPECT_EQ(largest, 24u);
  const HullInput same = loadReducedHullInput(par, *dir_, *dir_, {}, depth(7), {}, 1);
  EXPECT_EQ(same.reduction(0), 1);
  EXPECT_EQ(cv::countNonZero(same.mask(0) != full.mask(0)), 0);
}

TEST_F(ReducedViewSet, RefusesWhatTheFullResolutionLoadingRefuses) {
  const std::string par = *dir_ + "/scene_par.txt";
  const std::string other = test::temporaryDirectory();
  for (const auto& entry : std::filesystem::directory_iterator(*dir_)) {
    std::filesystem::copy(entry.path(), other + "/" + entry.path().filename().string());
  }
  // A mask of another size than its image, and a missing mask.
  cv::imwrite(other + "/view_0003.jpg", discMask(cv::Size(1200, 900)));
  try {
    loadReducedHullInput(other + "/scene_par.txt", *dir_, other, {}, depth(7), {}, 8);
    FAIL() << "a mask of another size was taken";
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find("view_0003.jpg: mask size differs"), std::string::npos)
        << e.what();
  }
  std::filesystem::remove(other + "/view_0005.jpg");
  cv::imwrite(other + "/view_0003.jpg", discMask(cv::Size(2400, 1800)));
  try {
    loadReducedHullInput(other + "/scene_par.txt", *dir_, other, {}, depth(7), {}, 8);
    FAIL() << "a missing mask was not noticed";
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find("view_0005.jpg"), std::string::npos) << e.what();
  }
  EXPECT_THROW(loadReducedHullInput(par, *dir_, *dir_, {}, depth(7), {}, 3), std::invalid_argument);
}

TEST_F(ReducedViewSet, TheHullCommandReportsItsReductionAndWritesFullSizeMasks) {
  const std::string out = test::temporaryDirectory();
  std::string stdout_text, stderr_text;
  const std::string common = "hull --calib " + *dir_ + "/scene_par.txt --images " + *dir_ +
                             " --silhouettes " + *dir_ + " --max-depth 7 --json";
  ASSERT_EQ(test::runProgram(common + " --out-silhouettes " + out, &stdout_text, &stderr_text), 0)
      << stderr_text;
  const nlohmann::json result = nlohmann::json::parse(stdout_text);
  EXPECT_EQ(result["input_reduction"]["min"], 4);
  EXPECT_EQ(result["input_reduction"]["max"], 4);
  EXPECT_EQ(result["input_reduction"]["image_size"], nlohmann::json({2400, 1800}));
  EXPECT_GT(result["reprojection_iou"]["mean"].get<double>(), 0.98);
  const cv::Mat written =
      cv::imread(out + "/view_0000.png", cv::IMREAD_GRAYSCALE);  // written as PNG
  ASSERT_EQ(written.size(), cv::Size(2400, 1800));
  const cv::Mat truth = cv::imread(*dir_ + "/view_0000.jpg", cv::IMREAD_GRAYSCALE) > 127;
  EXPECT_GT(maskIoU(written > 127, truth), 0.98);
  ASSERT_EQ(test::runProgram(common + " --max-input-reduction 1", &stdout_text, &stderr_text), 0)
      << stderr_text;
  const nlohmann::json full = nlohmann::json::parse(stdout_text);
  EXPECT_EQ(full["input_reduction"]["max"], 1);
  EXPECT_NEAR(full["reprojection_iou"]["mean"].get<double>(),
              result["reprojection_iou"]["mean"].get<double>(), 0.002);
  EXPECT_EQ(test::runProgram(common + " --max-input-reduction 3", &stdout_text, &stderr_text), 2);
  EXPECT_NE(stderr_text.find("--max-input-reduction must be 1, 2, 4 or 8"), std::string::npos)
      << stderr_text;
}

}  // namespace
}  // namespace sift_hull
