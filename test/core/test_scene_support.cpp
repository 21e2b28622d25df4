// The renderer's supports (SceneConfig::support): a floor or a turntable under the object, lit
// from above so that the object casts a shadow on it. The masks and depth maps stay the object's.
#include <gtest/gtest.h>

#include <cmath>
#include <fstream>
#include <limits>
#include <nlohmann/json.hpp>
#include <opencv2/imgproc.hpp>
#include <stdexcept>
#include <string>
#include <vector>

#include "common/test_data.h"
#include "sift_hull/synthetic/scene.h"

namespace sift_hull {
namespace {

constexpr double kPi = 3.14159265358979323846;
const std::vector<std::string> kSupports = {"floor", "turntable"};

SceneConfig supportedScene(const std::string& support, const std::string& layout, int views = 4) {
  SceneConfig config;
  config.views = views;
  config.width_px = 160;
  config.height_px = 120;
  config.layout = layout;
  config.support = support;
  return config;
}

/// Pixels of the view's ray, colour and place, walked for the pixels outside the mask.
template <typename Visit>
void forEachPixelOutside(const RenderedView& view, Visit visit) {
  for (int v = 0; v < view.mask.rows; ++v) {
    for (int u = 0; u < view.mask.cols; ++u) {
      if (view.mask.at<uint8_t>(v, u)) continue;
      visit(view.view.camera.rayDirection(Eigen::Vector2d(u, v)), view.image.at<cv::Vec3b>(v, u));
    }
  }
}

/// The turntable's saturated blue, lit or in shadow; the floor and the object have none of it.
bool discBlue(const cv::Vec3b& bgr) {
  return bgr[0] > 40 && bgr[0] > 1.6 * bgr[1] && bgr[0] > 3.0 * bgr[2];
}

TEST(SceneSupport, MasksAndDepthsAreThoseOfTheObjectAlone) {
  for (const char* layout : {"ring", "sphere"}) {
    for (const std::string& support : kSupports) {
      const SceneConfig config = supportedScene(support, layout);
      const Shape shape = Shape::byName(config.shape);
      for (const RenderedView& view : renderScene(config)) {
        const RenderedView bare =
            renderView(shape, view.view, view.mask.size(), config.seed, config.background, "none");
        const std::string where = std::string(layout) + " " + support + " " + view.view.name;
        EXPECT_EQ(cv::countNonZero(view.mask != bare.mask), 0) << where;
        EXPECT_EQ(cv::countNonZero(view.depth != bare.depth), 0) << where;
        cv::Mat finite = view.depth < std::numeric_limits<float>::infinity();
        EXPECT_EQ(cv::countNonZero(finite != view.mask), 0) << where << ": depth off the object";
        EXPECT_GT(cv::countNonZero(view.mask), 1000) << where;
      }
    }
  }
  // The ring's cameras do not move when a support comes.
  const Shape shape = Shape::byName(SceneConfig().shape);
  const std::vector<CalibratedView> bare = sceneCameras(supportedScene("none", "ring"), shape);
  const std::vector<CalibratedView> floor = sceneCameras(supportedScene("floor", "ring"), shape);
  ASSERT_EQ(bare.size(), floor.size());
  for (size_t i = 0; i < bare.size(); ++i) {
    EXPECT_EQ(bare[i].camera.projectionMatrix(), floor[i].camera.projectionMatrix());
  }
}

TEST(SceneSupport, TheFloorFillsWhatLiesBelowTheHorizonAndIsTextured) {
  for (const std::string& support : kSupports) {
    for (const char* background : {"black", "blue"}) {
      SceneConfig config = supportedScene(support, "sphere", 6);
      config.background = background;
      const cv::Vec3b sky =
          std::string(background) == "blue" ? cv::Vec3b(120, 50, 25) : cv::Vec3b(0, 0, 0);
      for (const RenderedView& view : renderScene(config)) {
        int below = 0, background_coloured = 0, above = 0, sky_coloured = 0;
        forEachPixelOutside(view, [&](const Eigen::Vector3d& ray, const cv::Vec3b& bgr) {
          if (ray.z() < -0.01) {
            ++below;
            background_coloured += bgr == sky;
          } else if (ray.z() > 0.01) {
            ++above;
            sky_coloured += bgr == sky;
          }
        });
        const std::string where = support + " " + background + " " + view.view.name;
        ASSERT_GT(below, 1000) << where;
        EXPECT_LT(background_coloured, 0.01 * below) << where;
        EXPECT_EQ(sky_coloured, above) << where << ": the floor shows above the horizon";
      }
    }
  }
  // Not a uniform colour: mottled tiles.
  const RenderedView view = renderSceneView(supportedScene("floor", "ring"), 0);
  cv::Mat outside;
  cv::bitwise_not(view.mask, outside);
  cv::Mat grey;
  cv::cvtColor(view.image, grey, cv::COLOR_BGR2GRAY);
  cv::Scalar mean, stddev;
  cv::meanStdDev(grey, mean, stddev, outside);
  EXPECT_GT(stddev[0], 12.0);
  EXPECT_GT(mean[0], 40.0);
}

/// Mean grey of the support's pixels near the object, in the object's shadow and in the light.
/// A pixel's support point (the floor, or the disc's top face for a turntable) is in shadow when
/// its ray toward the light hits the shape.
void shadowAndLight(const std::string& support_name, double* shadow_grey, double* lit_grey,
                    int* shadow_count) {
  SceneConfig config = supportedScene(support_name, "ring", 6);
  config.width_px = 320;
  config.height_px = 240;
  const Shape shape = Shape::byName(config.shape);
  const SceneSupport support = sceneSupport(shape, support_name);
  const Eigen::Vector2d centre = shape.boundingCentre().head<2>();
  // On the disc, its top face inside the light ring; on the floor, within 2.5 radii.
  const double reach =
      support.turntable ? 0.93 * support.disc_radius_m : 2.5 * shape.boundingRadius();
  double sums[2] = {0.0, 0.0};
  int counts[2] = {0, 0};
  for (const RenderedView& view : renderScene(config)) {
    const Eigen::Vector3d origin = view.view.camera.centre();
    forEachPixelOutside(view, [&](const Eigen::Vector3d& ray, const cv::Vec3b& bgr) {
      if (ray.z() >= 0.0) return;
      const Eigen::Vector3d X = origin + (support.stand_z - origin.z()) / ray.z() * ray;
      if ((X.head<2>() - centre).norm() > reach) return;
      RayHit hit;
      const int shadowed = shape.firstHit(X, support.light_W, &hit) ? 1 : 0;
      sums[shadowed] += (bgr[0] + bgr[1] + bgr[2]) / 3.0;
      ++counts[shadowed];
    });
  }
  *lit_grey = sums[0] / std::max(counts[0], 1);
  *shadow_grey = sums[1] / std::max(counts[1], 1);
  *shadow_count = counts[1];
}

TEST(SceneSupport, TheObjectCastsAClearlyDarkerShadow) {
  for (const std::string& support : kSupports) {
    double shadow = 0.0, lit = 0.0;
    int shadow_pixels = 0;
    shadowAndLight(support, &shadow, &lit, &shadow_pixels);
    EXPECT_GT(shadow_pixels, 500) << support << ": no shadow in sight";
    EXPECT_GT(lit, 40.0) << support;
    // Ambient only in shadow: 0.35 of the light's 0.35 + 0.65 cos(40 deg).
    EXPECT_LT(shadow, 0.6 * lit) << support << ": shadow " << shadow << ", lit " << lit;
    EXPECT_GT(shadow, 0.25 * lit) << support << ": a shadow keeps the ambient light";
  }
}

TEST(SceneSupport, TheTurntableShowsInEveryView) {
  for (const char* layout : {"ring", "sphere"}) {
    for (const std::string& support : kSupports) {
      for (const RenderedView& view : renderScene(supportedScene(support, layout, 8))) {
        int blue = 0;
        forEachPixelOutside(
            view, [&](const Eigen::Vector3d&, const cv::Vec3b& bgr) { blue += discBlue(bgr); });
        const std::string where = std::string(layout) + " " + support + " " + view.view.name;
        if (support == "turntable") {
          EXPECT_GT(blue, 0.03 * view.mask.total()) << where;
        } else {
          EXPECT_EQ(blue, 0) << where;
        }
      }
    }
  }
}

TEST(SceneSupport, TheSphereLayoutKeepsTheCamerasAboveTheFloor) {
  for (const std::string& support : kSupports) {
    const SceneConfig config = supportedScene(support, "sphere", 40);
    const Shape shape = Shape::byName(config.shape);
    const SceneSupport floor = sceneSupport(shape, support);
    double lowest = 90.0, highest = -90.0;
    for (const CalibratedView& view : sceneCameras(config, shape)) {
      const Eigen::Vector3d offset = view.camera.centre() - shape.boundingCentre();
      const double elevation = std::asin(offset.z() / offset.norm()) * 180.0 / kPi;
      lowest = std::min(lowest, elevation);
      highest = std::max(highest, elevation);
      EXPECT_GT(view.camera.centre().z(), floor.stand_z + 0.5) << view.name;
    }
    EXPECT_GE(lowest, 10.0 - 1e-9) << support;
    EXPECT_LE(highest, 70.0 + 1e-9) << support;
    EXPECT_LT(lowest, 12.0) << support;
    EXPECT_GT(highest, 68.0) << support;
  }
  // Without a support the sphere layout still looks from below.
  const Shape shape = Shape::byName(SceneConfig().shape);
  double lowest = 0.0;
  for (const CalibratedView& view : sceneCameras(supportedScene("none", "sphere", 40), shape)) {
    lowest = std::min(lowest, view.camera.centre().z() - shape.boundingCentre().z());
  }
  EXPECT_LT(lowest, -2.0);
  // A ring below (or at) the floor is refused.
  SceneConfig low_ring = supportedScene("floor", "ring");
  low_ring.ring_elevation_deg = 2.0;
  EXPECT_THROW(validate(low_ring), std::invalid_argument);
  low_ring.support = "none";
  EXPECT_NO_THROW(validate(low_ring));
}

TEST(SceneSupport, IsWrittenReadBackAndCheckedByName) {
  const std::string dir = test::temporaryDirectory();
  SceneConfig config = supportedScene("turntable", "sphere", 2);
  writeScene(dir, config, renderScene(config));
  EXPECT_EQ(readScene(dir).config.support, "turntable");
  EXPECT_EQ(readScene(dir).config.layout, "sphere");
  // A scene.json written before supports existed reads as "none".
  nlohmann::json json;
  std::ifstream(dir + "/scene.json") >> json;
  json.erase("support");
  std::ofstream(dir + "/scene.json") << json.dump(2);
  EXPECT_EQ(readScene(dir).config.support, "none");

  config.support = "table";
  try {
    validate(config);
    ADD_FAILURE() << "validate took support 'table'";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("none, floor or turntable"), std::string::npos)
        << e.what();
  }
  EXPECT_THROW(sceneSupport(Shape::byName("sphere"), "table"), std::invalid_argument);
  std::string out, err;
  EXPECT_EQ(test::runProgram("scene --out " + dir + "/x --support table", &out, &err), 2);
  EXPECT_NE(err.find("support must be none, floor or turntable"), std::string::npos) << err;
  EXPECT_EQ(test::runProgram("scene --out " + dir +
                                 "/y --views 1 --size 64x48 --support floor "
                                 "--json",
                             &out, &err),
            0)
      << err;
  EXPECT_EQ(nlohmann::json::parse(out).at("support"), "floor");
  EXPECT_EQ(readScene(dir + "/y").config.support, "floor");
}

}  // namespace
}  // namespace sift_hull
