// Cameras with lens distortion end to end, on the renderer's ground truth: the renderer's
// --distortion, the COLMAP model it writes, the hull carving raw silhouettes (equal to the hull of
// an ideal lens within a voxel) and the epipolar filter undistorting points before F.

#include <gtest/gtest.h>

#include <iostream>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "common/test_data.h"
#include "sift_hull/eval/hull_evaluation.h"
#include "sift_hull/filters/epipolar.h"
#include "sift_hull/hull/hull_pipeline.h"
#include "sift_hull/io/colmap.h"
#include "sift_hull/synthetic/mask_render.h"
#include "sift_hull/synthetic/scene.h"
#include "sift_hull/synthetic/shape.h"

namespace sift_hull {
namespace {

const LensDistortion kBarrel{-0.3, 0.1, 0.002, -0.001, 0.0};

SceneConfig ring(const LensDistortion& distortion) {
  SceneConfig config = test::smallRing();
  config.views = 10;
  config.distortion = distortion;
  return config;
}

/// Whether every occupied voxel of `a` has an occupied voxel of `b` within one voxel (26-
/// neighbourhood).
bool withinOneVoxel(const DenseGrid& a, const DenseGrid& b, size_t* misses) {
  *misses = 0;
  const int n = a.cells;
  for (int k = 0; k < n; ++k) {
    for (int j = 0; j < n; ++j) {
      for (int i = 0; i < n; ++i) {
        if (!a.occupied[a.index(i, j, k)]) continue;
        bool near = false;
        for (int dk = -1; dk <= 1 && !near; ++dk) {
          for (int dj = -1; dj <= 1 && !near; ++dj) {
            for (int di = -1; di <= 1 && !near; ++di) {
              const int x = i + di, y = j + dj, z = k + dk;
              near = x >= 0 && y >= 0 && z >= 0 && x < n && y < n && z < n &&
                     b.occupied[b.index(x, y, z)];
            }
          }
        }
        *misses += !near;
      }
    }
  }
  return *misses == 0;
}

TEST(DistortedScene, HullEqualsTheIdealLensHullWithinAVoxel) {
  const HullInput ideal = hullInputOf(renderScene(ring({})));
  const HullInput distorted = hullInputOf(renderScene(ring(kBarrel)));
  ASSERT_TRUE(distorted.cameras[0].distorted());
  // The lens moves the silhouettes by pixels: the raw masks differ from the ideal ones.
  EXPECT_LT(maskIoU(ideal.masks[0], distorted.masks[0]), 0.99);
  HullConfig config;
  config.max_depth = 6;
  const HullResult reference = buildHull(ideal, config);
  const HullResult result = buildHull(distorted, config, reference.box);
  const int cells = 1 << config.max_depth;
  const DenseGrid a = denseCarving(result.hull.views(), result.hull.cube().box(), cells, 2);
  const DenseGrid b = denseCarving(reference.hull.views(), reference.hull.cube().box(), cells, 2);
  size_t misses = 0;
  EXPECT_TRUE(withinOneVoxel(a, b, &misses)) << misses << " voxels";
  EXPECT_TRUE(withinOneVoxel(b, a, &misses)) << misses << " voxels";
  // The octree's classification under distortion agrees with brute-force carving of raw masks.
  EXPECT_GT(volumeIoU(result.hull, a), 0.98);
  EXPECT_GT(reprojectionIoU(result.mesh, result.hull.views()).min, 0.98);
  // The LP's box from undistorted bounds holds the ideal lens's box (same object, same cameras).
  const HullResult own_box = buildHull(distorted, config);
  const double voxel = reference.box.size().maxCoeff() / cells;
  EXPECT_LT((own_box.box.min_W - reference.box.min_W).cwiseAbs().maxCoeff(), voxel);
  EXPECT_LT((own_box.box.max_W - reference.box.max_W).cwiseAbs().maxCoeff(), voxel);
}

TEST(DistortedScene, ReducedDistanceMapsKeepTheHullOfADistortedHighResolutionSet) {
  SceneConfig config = ring(kBarrel);
  config.views = 8;
  config.width_px = 2400;
  config.height_px = 1800;
  const Shape shape = Shape::byName(config.shape);
  HullInput input;
  for (const CalibratedView& view : sceneCameras(config, shape)) {
    input.names.push_back(view.name);
    input.cameras.push_back(view.camera);
    input.masks.push_back(renderMask(shape, view.camera, {config.width_px, config.height_px}));
  }
  HullConfig full;
  full.max_depth = 7;
  full.distance_reduction = 1;
  HullConfig reduced = full;
  reduced.distance_reduction = 3;
  const HullResult a = buildHull(input, full);
  const HullResult b = buildHull(input, reduced, a.box);
  ASSERT_EQ(b.hull.views()[0].distanceReduction(), 3);
  const double iou_full = reprojectionIoU(a.mesh, a.hull.views()).mean;
  const double iou_reduced = reprojectionIoU(b.mesh, b.hull.views()).mean;
  EXPECT_GT(iou_full, 0.98);
  EXPECT_NEAR(iou_reduced, iou_full, 0.002);
  std::cout << "mean reprojection IoU, full " << iou_full << ", reduced by 3 " << iou_reduced
            << ", distance stage " << a.time.distance_ms << " / " << b.time.distance_ms << " ms\n";
}

TEST(DistortedScene, HullRefusesADistortionThatFoldsOverInTheImage) {
  HullInput input = hullInputOf(renderScene(ring({})));
  input.cameras[3] = input.cameras[3].withDistortion({-1.5, 0.0, 0.0, 0.0, 0.0});
  try {
    buildHull(input, HullConfig());
    FAIL() << "no error";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("view_0003.png"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("folds over"), std::string::npos) << e.what();
  }
}

TEST(DistortedScene, ColmapTextRoundTripKeepsTheDistortion) {
  std::vector<CalibratedView> views;
  for (const RenderedView& view : renderScene(ring(kBarrel))) views.push_back(view.view);
  views[1].camera = views[1].camera.withDistortion({0.1, -0.02, 0.0, 0.0, 0.004});  // FULL_OPENCV
  views[2].camera = views[2].camera.withDistortion({});                             // PINHOLE
  const std::string dir = test::temporaryDirectory() + "/sparse";
  writeColmapText(dir, views, 320, 240);
  const std::vector<CalibratedView> back = readColmapModel(dir);
  ASSERT_EQ(back.size(), views.size());
  EXPECT_EQ(back[0].camera_model, "OPENCV");
  EXPECT_EQ(back[1].camera_model, "FULL_OPENCV");
  EXPECT_EQ(back[2].camera_model, "PINHOLE");
  for (size_t i = 0; i < views.size(); ++i) {
    EXPECT_EQ(back[i].name, views[i].name);
    EXPECT_LT((back[i].camera.projectionMatrix() - views[i].camera.projectionMatrix())
                  .cwiseAbs()
                  .maxCoeff(),
              1e-9);
    const LensDistortion &d = back[i].camera.distortion(), &e = views[i].camera.distortion();
    EXPECT_EQ(d.k1, e.k1);
    EXPECT_EQ(d.k2, e.k2);
    EXPECT_EQ(d.p1, e.p1);
    EXPECT_EQ(d.p2, e.p2);
    EXPECT_EQ(d.k3, e.k3);
  }
  views[0].camera = views[0].camera.negated();
  EXPECT_THROW(writeColmapText(dir, views, 320, 240), std::runtime_error);
  EXPECT_THROW(writeMiddleburyPar(dir + "/par.txt", views), std::runtime_error);
}

/// Exact correspondences over the whole left image: raw pixels of the left view back-projected to
/// depths in [3, 5] m and projected into the right view (kept when inside it).
PutativeMatches exactMatches(const PinholeCamera& left, const PinholeCamera& right, cv::Size size) {
  PutativeMatches matches;
  matches.left_image_size = matches.right_image_size = size;
  cv::RNG rng(7);
  while (matches.matches.size() < 400) {
    const Eigen::Vector2d a(rng.uniform(0.0, size.width - 1.0),
                            rng.uniform(0.0, size.height - 1.0));
    const Eigen::Vector2d b = right.project(left.backProject(a, rng.uniform(3.0, 5.0)));
    if (!(b.x() >= 0 && b.y() >= 0 && b.x() <= size.width - 1 && b.y() <= size.height - 1))
      continue;
    const int i = static_cast<int>(matches.matches.size());
    matches.left_keypoints.emplace_back(cv::Point2f(a.x(), a.y()), 4.0f);
    matches.right_keypoints.emplace_back(cv::Point2f(b.x(), b.y()), 4.0f);
    matches.matches.emplace_back(i, i, 0.0f);
  }
  return matches;
}

TEST(DistortedScene, EpipolarFilterUndistortsPointsBeforeF) {
  const SceneConfig config = ring(kBarrel);
  const std::vector<CalibratedView> views = sceneCameras(config, Shape::byName(config.shape));
  const PinholeCamera &left = views[0].camera, &right = views[2].camera;
  PutativeMatches input = exactMatches(left, right, {config.width_px, config.height_px});
  calibratePair(&input, left, right);
  const FilterResult undistorted = filterEpipolar(input, EpipolarConfig());
  input.cameras.reset();  // F alone, on raw pixels: the lens bends the epipolar lines
  const FilterResult raw = filterEpipolar(input, EpipolarConfig());
  size_t kept_undistorted = 0, kept_raw = 0;
  double worst = 0.0;
  for (size_t m = 0; m < input.matches.size(); ++m) {
    kept_undistorted += undistorted.keep[m];
    kept_raw += raw.keep[m];
    worst = std::max(worst, undistorted.score[m]);
  }
  EXPECT_EQ(kept_undistorted, input.matches.size());
  EXPECT_LT(worst, 1e-3);  // exact correspondences lie on the curves (float keypoints)
  EXPECT_LT(kept_raw, input.matches.size() * 9 / 10) << "the distortion does not matter here";
}

TEST(DistortedScene, SceneCommandWritesAColmapModelAndTheHullReadsIt) {
  const std::string dir = test::temporaryDirectory();
  std::string out, err;
  ASSERT_EQ(test::runProgram("scene --out " + dir + " --views 8 --size 320x240 --distortion " +
                                 "-0.3,0.1,0.002,-0.001",
                             &out, &err),
            0)
      << err;
  EXPECT_FALSE(test::fileExists(dir + "/scene_par.txt"));
  EXPECT_EQ(sceneCalibration(dir), dir + "/sparse");
  EXPECT_EQ(readScene(dir).views[0].camera.distortion().k1, -0.3);
  ASSERT_EQ(test::runProgram("hull --calib " + dir + "/sparse --images " + dir + " --silhouettes " +
                                 dir + "/masks --max-depth 7 --json",
                             &out, &err),
            0)
      << err;
  EXPECT_GT(nlohmann::json::parse(out)["reprojection_iou"]["min"].get<double>(), 0.98) << out;
  ASSERT_EQ(test::runProgram("dataset-info --calib " + dir + "/sparse --images " + dir, &out, &err),
            0)
      << err;
  EXPECT_NE(out.find("OPENCV, k1=-0.3"), std::string::npos) << out;
}

TEST(DistortedScene, TheMatchCommandRefusesAFoldingDistortionAsTheHullDoes) {
  const std::string dir = test::temporaryDirectory();
  std::string out, err;
  ASSERT_EQ(test::runProgram("scene --out " + dir + " --views 4 --size 320x240", &out, &err), 0)
      << err;
  std::vector<CalibratedView> views = readCalibration(dir + "/scene_par.txt");
  for (CalibratedView& view : views) {
    view.camera = view.camera.withDistortion({-1.5, 0.0, 0.0, 0.0, 0.0});
  }
  writeColmapText(dir + "/folded", views, 320, 240);
  const std::string folds =
      "its lens distortion folds over within its 320x240 image (no one-to-one undistortion)";
  EXPECT_EQ(test::runProgram("match " + dir + "/view_0000.png " + dir + "/view_0001.png --calib " +
                                 dir + "/folded --filter epipolar",
                             &out, &err),
            1);
  EXPECT_NE(err.find(dir + "/folded: view 'view_0000.png': " + folds), std::string::npos) << err;
  EXPECT_EQ(test::runProgram("hull --calib " + dir + "/folded --images " + dir + " --silhouettes " +
                                 dir + "/masks --max-depth 5",
                             &out, &err),
            1);
  EXPECT_NE(err.find(folds), std::string::npos) << err;
  // A lens that does not fold within its image is matched as before.
  for (CalibratedView& view : views) view.camera = view.camera.withDistortion(kBarrel);
  writeColmapText(dir + "/barrel", views, 320, 240);
  EXPECT_EQ(test::runProgram("match " + dir + "/view_0000.png " + dir + "/view_0001.png --calib " +
                                 dir + "/barrel --filter epipolar",
                             &out, &err),
            0)
      << err;
}

TEST(DistortedScene, BadDistortionOptionsAreUsageErrors) {
  const std::string dir = test::temporaryDirectory();
  std::string out, err;
  for (const std::string bad : {"0.1,0.2", "0.1,x,0,0", "1,2,3,4,5,6", "nan,0,0,0", ""}) {
    EXPECT_EQ(test::runProgram("scene --out " + dir + " --views 2 --distortion '" + bad + "'", &out,
                               &err),
              2)
        << bad;
    EXPECT_NE(err.find("--distortion"), std::string::npos) << err;
  }
  EXPECT_EQ(
      test::runProgram("scene --out " + dir + " --views 2 --distortion -1.5,0,0,0", &out, &err), 2);
  EXPECT_NE(err.find("folds over"), std::string::npos) << err;
}

}  // namespace
}  // namespace sift_hull
