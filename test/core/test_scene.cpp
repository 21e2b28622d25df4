#include <gtest/gtest.h>

#include <fstream>
#include <iostream>
#include <opencv2/features2d.hpp>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>
#include <random>

#include "common/test_data.h"
#include "sift_hull/geometry/correspondence.h"
#include "sift_hull/hull/silhouette.h"
#include "sift_hull/io/calibration.h"
#include "sift_hull/io/images.h"
#include "sift_hull/io/pfm.h"
#include "sift_hull/synthetic/scene.h"

namespace sift_hull {
namespace {

/// True when any of the evenly spaced samples along the pixel's ray, through the shape's bounding
/// sphere, lies inside the solid.
bool rayEntersSolid(const Shape& shape, const PinholeCamera& camera, int u, int v, int samples) {
  const Eigen::Vector3d origin = camera.centre();
  const Eigen::Vector3d direction = camera.rayDirection(Eigen::Vector2d(u, v));
  const double to_centre = (shape.boundingCentre() - origin).norm();
  const double first = to_centre - shape.boundingRadius();
  const double step = 2.0 * shape.boundingRadius() / samples;
  for (int i = 0; i <= samples; ++i) {
    if (shape.contains(origin + (first + i * step) * direction)) return true;
  }
  return false;
}

/// Reference silhouette by brute force, sharing no ray intersection formula with the renderer:
/// coarse sampling along every ray, then much finer sampling where the coarse mask changes nearby
/// (grazing rays near a silhouette edge have short chords through the solid).
cv::Mat referenceSilhouette(const Shape& shape, const PinholeCamera& camera, cv::Size size) {
  cv::Mat coarse(size, CV_8UC1);
  for (int v = 0; v < size.height; ++v) {
    for (int u = 0; u < size.width; ++u) {
      coarse.at<uint8_t>(v, u) = rayEntersSolid(shape, camera, u, v, 400) ? 255 : 0;
    }
  }
  cv::Mat grown, shrunk, refined = coarse.clone();
  cv::dilate(coarse, grown, cv::Mat());
  cv::erode(coarse, shrunk, cv::Mat());
  for (int v = 0; v < size.height; ++v) {
    for (int u = 0; u < size.width; ++u) {
      if (grown.at<uint8_t>(v, u) != shrunk.at<uint8_t>(v, u) && !coarse.at<uint8_t>(v, u)) {
        refined.at<uint8_t>(v, u) = rayEntersSolid(shape, camera, u, v, 20000) ? 255 : 0;
      }
    }
  }
  return refined;
}

double intersectionOverUnion(const cv::Mat& a, const cv::Mat& b) {
  cv::Mat both, either;
  cv::bitwise_and(a, b, both);
  cv::bitwise_or(a, b, either);
  return static_cast<double>(cv::countNonZero(both)) / cv::countNonZero(either);
}

class SceneShapes : public ::testing::TestWithParam<std::string> {};

TEST_P(SceneShapes, SilhouetteEqualsProjectionOfAnalyticObject) {
  SceneConfig config;
  config.shape = GetParam();
  config.views = 3;
  config.layout = "sphere";
  config.width_px = 160;
  config.height_px = 120;
  const Shape shape = Shape::byName(config.shape);
  for (const RenderedView& view : renderScene(config)) {
    const cv::Mat reference = referenceSilhouette(shape, view.view.camera, view.mask.size());
    ASSERT_GT(cv::countNonZero(reference), 1000);
    EXPECT_GT(intersectionOverUnion(view.mask, reference), 0.999) << view.view.name;
  }
}

INSTANTIATE_TEST_SUITE_P(AllShapes, SceneShapes, ::testing::ValuesIn(Shape::names()));

TEST(Shape, BoundingBoxIsTight) {
  std::mt19937 rng(4);
  for (const std::string& name : Shape::names()) {
    const Shape shape = Shape::byName(name);
    Eigen::Vector3d lo, hi;
    shape.boundingBox(&lo, &hi);
    Eigen::Vector3d seen_lo = hi, seen_hi = lo;
    std::uniform_real_distribution<double> unit(0.0, 1.0);
    for (int i = 0; i < 400000; ++i) {
      const Eigen::Vector3d X =
          lo + (hi - lo).cwiseProduct(Eigen::Vector3d(unit(rng), unit(rng), unit(rng)));
      if (!shape.contains(X)) continue;
      seen_lo = seen_lo.cwiseMin(X);
      seen_hi = seen_hi.cwiseMax(X);
    }
    // Samples inside the solid reach within 3 % of the box edge of every face.
    EXPECT_LT(((seen_lo - lo).cwiseQuotient(hi - lo)).maxCoeff(), 0.03) << name;
    EXPECT_LT(((hi - seen_hi).cwiseQuotient(hi - lo)).maxCoeff(), 0.03) << name;
    EXPECT_LE((shape.boundingCentre() - 0.5 * (lo + hi)).norm(), 1e-12) << name;
  }
}

/// Renders the default scene once into a temporary directory, shared by the tests below.
class WrittenScene : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    config_.views = 6;
    config_.width_px = 320;
    config_.height_px = 240;
    directory_ = test::temporaryDirectory();
    rendered_ = renderScene(config_);
    writeScene(directory_, config_, rendered_);
  }
  static SceneConfig config_;
  static std::string directory_;
  static std::vector<RenderedView> rendered_;
};
SceneConfig WrittenScene::config_;
std::string WrittenScene::directory_;
std::vector<RenderedView> WrittenScene::rendered_;

TEST_F(WrittenScene, ReadsBackExactly) {
  const SceneData scene = readScene(directory_);
  EXPECT_EQ(scene.config.shape, config_.shape);
  ASSERT_EQ(scene.views.size(), rendered_.size());
  for (size_t i = 0; i < rendered_.size(); ++i) {
    EXPECT_EQ(scene.views[i].camera.projectionMatrix(),
              rendered_[i].view.camera.projectionMatrix());
    EXPECT_EQ(cv::norm(scene.depths[i], rendered_[i].depth, cv::NORM_INF), 0.0);
    const cv::Mat image = cv::imread(directory_ + "/" + scene.views[i].name);
    EXPECT_EQ(cv::norm(image, rendered_[i].image, cv::NORM_INF), 0.0);
    const cv::Mat mask =
        cv::imread(directory_ + "/masks/" + scene.views[i].name, cv::IMREAD_GRAYSCALE);
    EXPECT_EQ(cv::norm(mask, rendered_[i].mask, cv::NORM_INF), 0.0);
  }
}

TEST_F(WrittenScene, SilhouettesLoadFromMasksAndFromImages) {
  const SceneData scene = readScene(directory_);
  const std::vector<cv::Mat> from_masks =
      loadSilhouettes(scene.views, directory_, directory_ + "/" + kMaskDirectory, {});
  SilhouetteConfig dark_background;  // the scene's background is black: a low threshold suffices
  dark_background.silhouette_method = "threshold";
  dark_background.threshold = 0.02;
  dark_background.dilate_px = dark_background.erode_px = 1;
  const std::vector<cv::Mat> from_images =
      loadSilhouettes(scene.views, directory_, "", dark_background);
  ASSERT_EQ(from_masks.size(), rendered_.size());
  for (size_t i = 0; i < rendered_.size(); ++i) {
    EXPECT_EQ(cv::norm(from_masks[i], rendered_[i].mask, cv::NORM_INF), 0.0);
    EXPECT_GT(intersectionOverUnion(from_images[i], rendered_[i].mask), 0.99);
  }
  const std::string other = test::temporaryDirectory();
  cv::imwrite(other + "/" + scene.views[0].name, cv::Mat(10, 10, CV_8UC1, cv::Scalar(255)));
  try {
    loadSilhouettes({scene.views[0]}, directory_, other, {});
    FAIL() << "expected an error";
  } catch (const std::runtime_error& e) {
    EXPECT_EQ(std::string(e.what()), other + "/view_0000.png: mask size differs from the image's");
  }
}

TEST_F(WrittenScene, RenderingIsDeterministic) {
  const std::vector<RenderedView> again = renderScene(config_);
  EXPECT_EQ(cv::norm(again[2].image, rendered_[2].image, cv::NORM_INF), 0.0);
  SceneConfig other = config_;
  other.seed = config_.seed + 1;
  EXPECT_GT(cv::norm(renderScene(other)[2].image, rendered_[2].image, cv::NORM_L1), 0.0);
}

TEST_F(WrittenScene, BackgroundHasInfiniteDepthAndObjectPositiveDepth) {
  const RenderedView& view = rendered_[0];
  for (int v = 0; v < view.mask.rows; ++v) {
    for (int u = 0; u < view.mask.cols; ++u) {
      const float depth = view.depth.at<float>(v, u);
      ASSERT_EQ(view.mask.at<uint8_t>(v, u) == 0, std::isinf(depth)) << u << "," << v;
      if (!std::isinf(depth)) {
        ASSERT_GT(depth, 0.0f);
      }
    }
  }
}

TEST(SceneTexture, IsRichEnoughForSift) {
  SceneConfig config;  // the default 640x480 scene
  const Shape shape = Shape::byName(config.shape);
  const RenderedView view = renderView(shape, sceneCameras(config, shape)[0],
                                       {config.width_px, config.height_px}, config.seed);
  std::vector<cv::KeyPoint> keypoints;
  cv::SIFT::create()->detect(view.image, keypoints, view.mask);
  std::cout << keypoints.size() << " SIFT keypoints\n";
  EXPECT_GT(keypoints.size(), 500u);
}

/// Analytic visibility of X in a camera: the first hit along the camera's ray to X is X itself.
Visibility analyticVisibility(const Shape& shape, const PinholeCamera& camera,
                              const Eigen::Vector3d& X, cv::Size size, bool* ambiguous) {
  const Eigen::Vector2d pixel = camera.project(X);
  *ambiguous = false;
  if (pixel.x() < -0.5 || pixel.y() < -0.5 || pixel.x() > size.width - 0.5 ||
      pixel.y() > size.height - 0.5) {
    return Visibility::kOutsideImage;
  }
  const Eigen::Vector3d offset = X - camera.centre();
  RayHit hit;
  if (!shape.firstHit(camera.centre(), offset.normalized(), &hit)) return Visibility::kVisible;
  const double gap = (offset.norm() - hit.distance_m) / offset.norm();
  *ambiguous = gap > 1e-6 && gap < 0.02;  // occluders this close fall within the depth tolerance
  return gap <= 1e-6 ? Visibility::kVisible : Visibility::kOccluded;
}

/// True when the depths of the pixels within 1.5 px of `pixel` differ by more than 1 %.
bool nearDepthEdge(const cv::Mat& depth, const Eigen::Vector2d& pixel) {
  float lo = std::numeric_limits<float>::infinity(), hi = 0.0f;
  for (int dv = -1; dv <= 2; ++dv) {
    for (int du = -1; du <= 2; ++du) {
      const int u = std::clamp(static_cast<int>(std::floor(pixel.x())) + du, 0, depth.cols - 1);
      const int v = std::clamp(static_cast<int>(std::floor(pixel.y())) + dv, 0, depth.rows - 1);
      lo = std::min(lo, depth.at<float>(v, u));
      hi = std::max(hi, depth.at<float>(v, u));
    }
  }
  return hi > 1.01f * lo;
}

struct CorrespondenceTally {
  int visible = 0, occluded = 0, checked = 0, undecided = 0, coarse_off_edges = 0;
};

/// Compares trueCorrespondence of one pixel of view a with the analytic answer, counting the
/// result.
void checkCorrespondence(const Shape& shape, const DepthView& a, const DepthView& b,
                         const Eigen::Vector2d& pixel, bool integer_pixel,
                         CorrespondenceTally* tally) {
  const TrueCorrespondence truth = trueCorrespondence(a, b, pixel);
  const Eigen::Vector3d origin = a.camera.centre(), direction = a.camera.rayDirection(pixel);
  RayHit hit;
  if (!shape.firstHit(origin, direction, &hit)) {
    if (integer_pixel) {
      EXPECT_EQ(truth.visibility, Visibility::kBackground) << pixel.transpose();
    }
    return;
  }
  if (truth.visibility == Visibility::kBackground) return;  // sub-pixel at the silhouette edge
  const Eigen::Vector3d X = origin + hit.distance_m * direction;
  const double error_px = (truth.pixel_b - b.camera.project(X)).norm();
  if (integer_pixel) {
    EXPECT_LT(error_px, 1e-3) << "pixel " << pixel.transpose();
  } else if (error_px > 0.05) {
    // Bilinear depth is exact only on planes: off them, and next to a depth edge where the nearest
    // pixel's depth is used, a sub-pixel look-up may miss by a fraction of a pixel.
    if (!nearDepthEdge(a.depth, pixel)) {
      EXPECT_LT(error_px, 0.5) << "pixel " << pixel.transpose();
      ++tally->coarse_off_edges;
    }
    return;
  }
  ++tally->checked;
  bool ambiguous;
  const Visibility expected = analyticVisibility(shape, b.camera, X, b.depth.size(), &ambiguous);
  if (ambiguous) return;
  // Within a pixel of a depth edge in view b, whether the point is seen depends on where in the
  // pixel the edge runs: the depth map cannot tell, so such samples are only counted.
  if (truth.visibility != expected && nearDepthEdge(b.depth, truth.pixel_b)) {
    ++tally->undecided;
    return;
  }
  EXPECT_EQ(truth.visibility, expected) << "pixel " << pixel.transpose();
  tally->visible += expected == Visibility::kVisible;
  tally->occluded += expected == Visibility::kOccluded;
}

TEST_F(WrittenScene, DepthCorrespondencesAgreeWithProjectedPoints) {
  const SceneData scene = readScene(directory_);
  const Shape shape = Shape::byName(scene.config.shape);
  std::mt19937 rng(12);
  std::uniform_real_distribution<double> u(0, scene.config.width_px - 1);
  std::uniform_real_distribution<double> v(0, scene.config.height_px - 1);
  CorrespondenceTally tally;
  for (const auto& [ia, ib] : std::vector<std::pair<int, int>>{{0, 1}, {0, 2}, {1, 4}}) {
    const DepthView a{scene.views[ia].camera, scene.depths[ia]};
    const DepthView b{scene.views[ib].camera, scene.depths[ib]};
    for (int trial = 0; trial < 10000; ++trial) {
      const bool integer_pixel = trial % 2 == 0;
      // Two statements: the order of two draws in one argument list is unspecified.
      const double v_px = v(rng);
      const double u_px = u(rng);
      Eigen::Vector2d pixel(u_px, v_px);
      if (integer_pixel) pixel = pixel.array().round();
      checkCorrespondence(shape, a, b, pixel, integer_pixel, &tally);
    }
  }
  std::cout << tally.checked << " samples checked: " << tally.visible << " visible, "
            << tally.occluded << " occluded, " << tally.undecided << " undecided at depth edges, "
            << tally.coarse_off_edges << " sub-pixel look-ups off by more than 0.05 px\n";
  EXPECT_LT(tally.undecided, 0.03 * tally.checked);  // measured: 89 of 4876 (1.8 %)
  EXPECT_LT(tally.coarse_off_edges, 0.01 * tally.checked);
  EXPECT_GT(tally.visible, 1000);
  EXPECT_GT(tally.occluded, 200);
}

TEST(SceneCommand, WritesTheSceneAndReportsJson) {
  const std::string dir = test::temporaryDirectory() + "/scene";
  std::string out, err;
  ASSERT_EQ(test::runProgram("scene --out " + dir + " --views 3 --size 64x48 --shape torus --json",
                             &out, &err),
            0)
      << err;
  EXPECT_NE(out.find("\"views\": 3"), std::string::npos) << out;
  EXPECT_NE(out.find("\"shape\": \"torus\""), std::string::npos) << out;
  const SceneData scene = readScene(dir);
  EXPECT_EQ(scene.views.size(), 3u);
  EXPECT_EQ(scene.depths[2].size(), cv::Size(64, 48));
  EXPECT_EQ(cv::imread(dir + "/masks/view_0002.png").size(), cv::Size(64, 48));
}

TEST(SceneCommand, TheCameraDistanceFlagIsReadAndTheOldNameRefused) {
  const std::string dir = test::temporaryDirectory();
  std::string out, err;
  const std::string scene = "scene --views 3 --size 64x48 --out " + dir;
  ASSERT_EQ(test::runProgram(scene + "/new --camera-distance-m 5", &out, &err), 0) << err;
  EXPECT_EQ(readScene(dir + "/new").config.camera_distance_m, 5.0);
  EXPECT_EQ(test::runProgram(scene + "/old --distance 5", &out, &err), 2);
  EXPECT_NE(err.find("unknown option --distance"), std::string::npos) << err;
}

TEST(SceneCommand, RejectsBadArgumentsWithUsageErrors) {
  const std::string unused = test::temporaryDirectory() + "/unused";
  std::string out, err;
  EXPECT_EQ(test::runProgram("scene --out " + unused + " --size 640", &out, &err), 2);
  EXPECT_NE(err.find("--size expects WIDTHxHEIGHT, got '640'"), std::string::npos) << err;
  EXPECT_EQ(test::runProgram("scene --out " + unused + " --shape cube", &out, &err), 2);
  EXPECT_NE(err.find("unknown shape 'cube'"), std::string::npos) << err;
  EXPECT_EQ(test::runProgram("scene --views 3", &out, &err), 2);
  EXPECT_NE(err.find("missing required option --out"), std::string::npos) << err;
  EXPECT_EQ(test::runProgram("scene --help", &out, &err), 0);
  EXPECT_NE(out.find("usage: sift_hull scene"), std::string::npos);
}

TEST(Correspondence, DegenerateInputsGiveDefinedAnswers) {
  const PinholeCamera camera =
      PinholeCamera::fromCentre((Eigen::Matrix3d() << 100, 0, 0, 0, 100, 0, 0, 0, 1).finished(),
                                Eigen::Matrix3d::Identity(), Eigen::Vector3d(0, 0, -2));
  const DepthView one_pixel{camera, cv::Mat(1, 1, CV_32FC1, cv::Scalar(2.0f))};
  double depth;
  EXPECT_TRUE(sampleDepth(one_pixel.depth, {0.2, -0.3}, &depth));
  EXPECT_EQ(depth, 2.0);
  EXPECT_FALSE(sampleDepth(one_pixel.depth, {NAN, 0.0}, &depth));
  EXPECT_EQ(trueCorrespondence(one_pixel, one_pixel, {NAN, NAN}).visibility,
            Visibility::kBackground);
  EXPECT_EQ(trueCorrespondence(one_pixel, one_pixel, {0.0, 0.0}).visibility, Visibility::kVisible);
  EXPECT_EQ(trueCorrespondence(one_pixel, one_pixel, {5.0, 0.0}).visibility,
            Visibility::kBackground);
}

TEST(DepthIo, PfmRoundTripKeepsInfinityAndOrientation) {
  cv::Mat depth(3, 4, CV_32FC1);
  for (int i = 0; i < 12; ++i) depth.at<float>(i / 4, i % 4) = 0.5f * i;
  depth.at<float>(0, 1) = std::numeric_limits<float>::infinity();
  const std::string path = test::temporaryDirectory() + "/d.pfm";
  writePfm(path, depth);
  const cv::Mat back = readPfm(path);
  ASSERT_EQ(back.size(), depth.size());
  EXPECT_EQ(back.at<float>(2, 3), 5.5f);
  EXPECT_TRUE(std::isinf(back.at<float>(0, 1)));
}

TEST(DepthIo, PfmBytesFollowTheFormat) {
  cv::Mat depth(2, 1, CV_32FC1);
  depth.at<float>(0, 0) = 1.0f;  // top row
  depth.at<float>(1, 0) = 2.0f;  // bottom row, stored first
  const std::string path = test::temporaryDirectory() + "/d.pfm";
  writePfm(path, depth);
  std::ifstream in(path, std::ios::binary);
  const std::string bytes(std::istreambuf_iterator<char>(in), {});
  const std::string header = "Pf\n1 2\n-1\n";
  ASSERT_EQ(bytes.size(), header.size() + 8);
  EXPECT_EQ(bytes.substr(0, header.size()), header);
  const std::string two_le("\x00\x00\x00\x40", 4), one_le("\x00\x00\x80\x3f", 4);
  EXPECT_EQ(bytes.substr(header.size(), 4), two_le);
  EXPECT_EQ(bytes.substr(header.size() + 4, 4), one_le);
}

TEST(DepthIo, TruncatedOrOversizedPfmIsRejected) {
  const std::string path = test::temporaryDirectory() + "/short.pfm";
  std::ofstream(path) << "Pf\n4 3\n-1\n1234";
  EXPECT_THROW(readPfm(path), ParseError);
  std::ofstream(path) << "Pf\n400000 300000\n-1\n";
  EXPECT_THROW(readPfm(path), ParseError);
  std::ofstream(path) << "PF\n4 3\n-1\n";
  EXPECT_THROW(readPfm(path), ParseError);
}

}  // namespace
}  // namespace sift_hull
