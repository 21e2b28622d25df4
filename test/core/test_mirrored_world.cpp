// Mirrored (left-handed) world frames and the sign of projection matrices: the hull of a mirrored
// scene is the mirrored hull, P and -P give one hull, and results that cannot be right are errors
// of `sift_hull hull` unless --allow-poor, on the renderer's ground truth.

#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <fstream>
#include <iomanip>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "common/test_data.h"
#include "sift_hull/eval/hull_evaluation.h"
#include "sift_hull/geometry/camera_set.h"
#include "sift_hull/hull/bounding_box.h"
#include "sift_hull/hull/hull_pipeline.h"
#include "sift_hull/hull/hull_stream.h"
#include "sift_hull/hull/mesh.h"
#include "sift_hull/io/calibration.h"
#include "sift_hull/synthetic/scene.h"

namespace sift_hull {
namespace {

/// Negates the world's x axis: X' = S X with S = diag(-1, 1, 1), so P' = P diag(-1, 1, 1, 1).
Matrix34d mirrored(const Matrix34d& P) {
  return P * Eigen::Vector4d(-1.0, 1.0, 1.0, 1.0).asDiagonal();
}

bool contains(const std::string& text, const std::string& part) {
  return text.find(part) != std::string::npos;
}

struct HullSummary {
  double volume_m3, iou_mean, mesh_volume;
  bool watertight;
  Box3d box;
};

HullSummary summarise(const HullInput& input, int depth) {
  HullConfig config;
  config.max_depth = depth;
  const HullResult result = buildHull(input, config);
  return {result.hull.stats().occupied_volume_m3,
          reprojectionIoU(result.mesh, result.hull.views()).mean, meshVolume(result.mesh),
          result.mesh_check.watertight, result.box};
}

/// The scene's cameras through their projection matrices, each transformed by `change`, then
/// decomposed and oriented as a projection list is.
template <typename Change>
std::vector<PinholeCamera> throughProjections(const std::vector<PinholeCamera>& cameras,
                                              Change change) {
  std::vector<PinholeCamera> result;
  for (size_t i = 0; i < cameras.size(); ++i) {
    result.push_back(PinholeCamera::fromProjection(change(i, cameras[i].projectionMatrix())));
  }
  orientCameras(&result);
  return result;
}

TEST(MirroredWorld, TheHullOfAMirroredSceneIsTheMirroredHull) {
  const HullInput normal = test::sceneHullInput("sculpture", 8, "sphere");
  HullInput mirror = normal;
  mirror.cameras =
      throughProjections(normal.cameras, [](size_t, const Matrix34d& P) { return mirrored(P); });
  for (const PinholeCamera& camera : mirror.cameras) {
    EXPECT_TRUE(camera.improper());
    EXPECT_GT(camera.depth(Eigen::Vector3d::Zero()), 0.0);
  }
  const HullSummary a = summarise(normal, 6), b = summarise(mirror, 6);
  EXPECT_NEAR(b.volume_m3, a.volume_m3, 0.01 * a.volume_m3);
  EXPECT_NEAR(b.iou_mean, a.iou_mean, 0.002);
  EXPECT_GT(a.iou_mean, 0.8);
  EXPECT_TRUE(b.watertight);
  EXPECT_GT(b.mesh_volume, 0.0);
  EXPECT_NEAR(b.mesh_volume, a.mesh_volume, 0.01 * a.mesh_volume);
  EXPECT_NEAR(b.box.min_W.x(), -a.box.max_W.x(), 1e-6);
  EXPECT_NEAR(b.box.max_W.x(), -a.box.min_W.x(), 1e-6);
  EXPECT_NEAR(b.box.min_W.y(), a.box.min_W.y(), 1e-6);
  EXPECT_NEAR(b.box.max_W.z(), a.box.max_W.z(), 1e-6);
}

TEST(MirroredWorld, EachViewsSignIsChosenSoThatTheSceneIsInFront) {
  const HullInput normal = test::sceneHullInput("sphere", 6, "ring");
  // -P for all views, and -P for one view only: the same cameras.
  for (int odd : {-1, 2}) {
    const std::vector<PinholeCamera> cameras =
        throughProjections(normal.cameras, [odd](size_t i, const Matrix34d& P) {
          return (odd < 0 || static_cast<int>(i) == odd) ? Matrix34d(-P) : P;
        });
    for (size_t i = 0; i < cameras.size(); ++i) {
      EXPECT_FALSE(cameras[i].improper());
      EXPECT_LT((cameras[i].R() - normal.cameras[i].R()).norm(), 1e-9) << i;
      EXPECT_LT((cameras[i].t() - normal.cameras[i].t()).norm(), 1e-9) << i;
    }
  }
  // The mirrored world with one view's P negated: that view is oriented too.
  const std::vector<PinholeCamera> cameras = throughProjections(
      normal.cameras,
      [](size_t i, const Matrix34d& P) { return i == 3 ? Matrix34d(-mirrored(P)) : mirrored(P); });
  for (const PinholeCamera& camera : cameras) {
    EXPECT_TRUE(camera.improper());
    EXPECT_GT(camera.depth(Eigen::Vector3d::Zero()), 0.0);
  }
}

TEST(MirroredWorld, OneMirroredCameraAmongRightHandedOnesIsNamed) {
  const HullInput normal = test::sceneHullInput("sphere", 6, "ring");
  std::vector<PinholeCamera> cameras;
  for (size_t i = 0; i < normal.cameras.size(); ++i) {
    const Matrix34d P = normal.cameras[i].projectionMatrix();
    cameras.push_back(PinholeCamera::fromProjection(i == 4 ? mirrored(P) : P));
  }
  try {
    orientCameras(&cameras, normal.names);
    FAIL() << "a camera of the other handedness was accepted";
  } catch (const std::invalid_argument& e) {
    EXPECT_TRUE(contains(e.what(), "'" + normal.names[4] + "'")) << e.what();
    EXPECT_FALSE(contains(e.what(), normal.names[3])) << e.what();
  }
}

TEST(MirroredWorld, AnEmptyBoxNamesTheCamerasThatSeeTheSceneBehindThem) {
  const HullInput input = test::ring(6);
  std::vector<PinholeCamera> cameras = input.cameras;
  cameras[2] = cameras[2].negated();  // its P's sign kept wrong: the object behind it
  std::vector<SilhouetteBounds> bounds;
  for (const cv::Mat& mask : input.masks) bounds.push_back(silhouetteBounds(mask, false));
  try {
    hullBoundingBox(cameras, bounds, input.names);
    FAIL() << "a box was found";
  } catch (const HullBoxError& e) {
    EXPECT_EQ(e.reason(), HullBoxError::Reason::kEmpty);
    EXPECT_TRUE(contains(e.what(), "behind '" + input.names[2] + "'")) << e.what();
  }
}

TEST(MirroredWorld, TheStreamRefusesAViewThatSeesTheGivenBoxBehindIt) {
  const HullInput input = test::ring(6);
  HullStreamConfig config = test::streamConfig(5);
  Box3d box;
  box.min_W = Eigen::Vector3d::Constant(-1.0);
  box.max_W = Eigen::Vector3d::Constant(1.0);
  config.box = box;
  HullStream stream(config);
  const PinholeCamera& camera = input.cameras[0];
  const Eigen::Matrix3d turn = Eigen::Vector3d(-1.0, 1.0, -1.0).asDiagonal();  // half a turn
  const PinholeCamera away =
      PinholeCamera::fromCentre(camera.K(), turn * camera.R(), camera.centre());
  EXPECT_EQ(stream.add("away", away, input.masks[0]), HullStream::Outcome::kRefused);
  const std::vector<std::string> refusals = stream.takeRefusals();
  ASSERT_EQ(refusals.size(), 1u);
  EXPECT_TRUE(contains(refusals[0], "sees the given box behind it")) << refusals[0];
  EXPECT_NE(stream.add(input.names[0], camera, input.masks[0]), HullStream::Outcome::kRefused);
}

/// The command line on a rendered scene: its par file, and projection lists made from it.
class MirroredCommandLine : public test::WrittenSceneSuite {
 protected:
  /// A projection list of the scene's views, each P transformed by `change`.
  template <typename Change>
  std::string projectionList(Change change) {
    const std::string path = test::temporaryDirectory() + "/projections.txt";
    std::ofstream out(path);
    out << std::setprecision(17);
    const std::vector<CalibratedView> views = readCalibration(*scene_ + "/scene_par.txt");
    for (size_t i = 0; i < views.size(); ++i) {
      const Matrix34d P = change(i, views[i].camera.projectionMatrix());
      out << views[i].name;
      for (int r = 0; r < 3; ++r) {
        for (int c = 0; c < 4; ++c) out << ' ' << P(r, c);
      }
      out << '\n';
    }
    return path;
  }

  /// Runs `hull --json` with `calib` (the par file by default); the JSON in `json` on success.
  int hull(const std::string& extra, nlohmann::json* json, std::string* err,
           const std::string& calib = "") {
    std::string out;
    const std::string par = calib.empty() ? *scene_ + "/scene_par.txt" : calib;
    const int code =
        test::runProgram("hull --json --calib " + par + " --images " + *scene_ + " --silhouettes " +
                             *scene_ + "/masks --max-depth 6 " + extra,
                         &out, err);
    if (code == 0) *json = nlohmann::json::parse(out);
    return code;
  }
};

TEST_F(MirroredCommandLine, MirroredAndNegatedListsGiveTheSameHull) {
  nlohmann::json normal, mirror, negated;
  std::string err;
  ASSERT_EQ(hull("", &normal, &err), 0) << err;
  ASSERT_EQ(hull("", &mirror, &err,
                 projectionList([](size_t, const Matrix34d& P) { return mirrored(P); })),
            0)
      << err;
  ASSERT_EQ(hull("", &negated, &err, projectionList([](size_t i, const Matrix34d& P) {
                   return i % 3 == 0 ? Matrix34d(-P) : P;
                 })),
            0)
      << err;
  const double leaves = normal["occupied_leaves"];
  EXPECT_NEAR(mirror["occupied_leaves"].get<double>(), leaves, 0.01 * leaves);
  EXPECT_EQ(negated["occupied_leaves"], normal["occupied_leaves"]);
  const double iou = normal["reprojection_iou"]["mean"];
  EXPECT_GT(iou, 0.8);
  EXPECT_NEAR(mirror["reprojection_iou"]["mean"].get<double>(), iou, 0.002);
  EXPECT_NEAR(negated["reprojection_iou"]["mean"].get<double>(), iou, 1e-9);
  EXPECT_TRUE(mirror["mesh"]["watertight"].get<bool>());
  EXPECT_NEAR(mirror["bbox"]["min"][0].get<double>(), -normal["bbox"]["max"][0].get<double>(),
              1e-6);
  EXPECT_TRUE(mirror["warnings"].empty());
}

TEST_F(MirroredCommandLine, AMixedHandednessListIsRefusedNamingTheCamera) {
  nlohmann::json json;
  std::string err;
  EXPECT_EQ(hull("", &json, &err, projectionList([](size_t i, const Matrix34d& P) {
                   return i == 5 ? mirrored(P) : P;
                 })),
            1);
  EXPECT_TRUE(contains(err, "'view_0005.png'")) << err;
  EXPECT_TRUE(contains(err, "cannot be oriented")) << err;
}

/// Each result that cannot be right: exit 1 with its reason, or 0 and a warning with --allow-poor.
TEST_F(MirroredCommandLine, PoorResultsAreErrorsUnlessAllowed) {
  const std::vector<CalibratedView> views = readCalibration(*scene_ + "/scene_par.txt");
  // A box behind views 0 and 1: their centres' mean, moved back along both optical axes.
  const PinholeCamera &a = views[0].camera, &b = views[1].camera;
  const Eigen::Vector3d behind =
      0.5 * (a.centre() + b.centre()) - 3.0 * (a.opticalAxis() + b.opticalAxis());
  ASSERT_LT(a.depth(behind), 0.0);
  ASSERT_LT(b.depth(behind), 0.0);
  std::ostringstream behind_box;
  behind_box << "--views " << views[0].name << "," << views[1].name << " --box " << behind.x() - 0.5
             << ',' << behind.y() - 0.5 << ',' << behind.z() - 0.5 << ',' << behind.x() + 0.5 << ','
             << behind.y() + 0.5 << ',' << behind.z() + 0.5;
  const struct {
    std::string arguments, reason;
  } cases[] = {
      {behind_box.str(), "no camera sees the --box in front of it"},
      {"--box -10,-10,-10,1000,1000,1000", "cameras' mutual distance"},
      {"--box 1.5,1.5,1.5,1.6,1.6,1.6", "the mesh has no faces"},
      {"--box 0,0,0,2,2,2", "the mean reprojection IoU is"},
  };
  for (const auto& c : cases) {
    nlohmann::json json;
    std::string err;
    EXPECT_EQ(hull(c.arguments, &json, &err), 1) << c.arguments;
    EXPECT_TRUE(contains(err, c.reason)) << c.arguments << ": " << err;
    EXPECT_TRUE(contains(err, "--allow-poor")) << err;
    ASSERT_EQ(hull(c.arguments + " --allow-poor", &json, &err), 0) << c.arguments << ": " << err;
    bool found = false;
    for (const auto& warning : json["warnings"]) found |= contains(warning, c.reason);
    EXPECT_TRUE(found) << c.arguments << ": " << json["warnings"].dump();
    EXPECT_TRUE(contains(err, "warning: ")) << err;
  }
}

}  // namespace
}  // namespace sift_hull
