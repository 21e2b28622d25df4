// Hostile input to the core and the command-line program: every case of docs/RELIABILITY.md that
// needs no ROS ends in a clear error (or a documented refusal) instead of a crash, a hang, an
// exhausted memory or a silently wrong result. The inputs of ../shared/repro are rebuilt here from
// the renderer, so these tests run without that directory; where it is present, its files are
// run as well.

#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <atomic>
#include <cmath>
#include <fstream>
#include <limits>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>
#include <stdexcept>
#include <thread>

#include "common/parallel.h"
#include "common/test_data.h"
#include "hull/distance_kernel.h"
#include "sift_hull/eval/match_evaluation.h"
#include "sift_hull/features/sift.h"
#include "sift_hull/filters/filter.h"
#include "sift_hull/hull/bounding_box.h"
#include "sift_hull/hull/hull_config.h"
#include "sift_hull/hull/hull_pipeline.h"
#include "sift_hull/hull/hull_stream.h"
#include "sift_hull/hull/hull_view.h"
#include "sift_hull/hull/octree.h"
#include "sift_hull/hull/silhouette.h"
#include "sift_hull/io/calibration.h"
#include "sift_hull/io/ground_truth_files.h"
#include "sift_hull/io/pfm.h"
#include "sift_hull/limits.h"
#include "sift_hull/synthetic/scene.h"

namespace sift_hull {
namespace {

using test::ring;
using test::streamConfig;

void writeText(const std::string& path, const std::string& text) {
  std::ofstream out(path, std::ios::binary);
  out << text;
}

bool contains(const std::string& text, const std::string& part) {
  return text.find(part) != std::string::npos;
}

TEST(LookUp, NonFiniteCoordinatesStayInsideTheMap) {
  const float map[] = {1, 2, 3, 4};  // 2x2
  const float high = detail::lookUpLimit(2);
  const float nan = std::numeric_limits<float>::quiet_NaN();
  const float inf = std::numeric_limits<float>::infinity();
  EXPECT_EQ(detail::lookUp(map, 2, high, high, nan, nan), 1.0f);
  EXPECT_EQ(detail::lookUp(map, 2, high, high, -inf, nan), 1.0f);
  EXPECT_NEAR(detail::lookUp(map, 2, high, high, inf, inf), 4.0f, 0.01f);
}

TEST(ParallelFor, AnExceptionInAWorkerReachesTheCaller) {
  EXPECT_THROW(detail::parallelFor(1000, 4,
                                   [&](size_t i) {
                                     if (i == 10) throw std::bad_alloc();
                                   }),
               std::bad_alloc);
  // On the caller's thread alone the order is fixed: the hand-out stops at the exception.
  int calls = 0;
  EXPECT_THROW(detail::parallelFor(1000, 1,
                                   [&](size_t i) {
                                     ++calls;
                                     if (i == 10) throw std::runtime_error("stop");
                                   }),
               std::runtime_error);
  EXPECT_EQ(calls, 11);
}

TEST(Limits, SettingsBeyondALimitAreRefusedNamingIt) {
  HullConfig hull;
  hull.max_depth = limits::kMaxHullDepth + 1;
  EXPECT_THROW(validate(hull), std::invalid_argument);
  hull.max_depth = 8;
  hull.threads = 100000;
  try {
    validate(hull);
    FAIL() << "threads 100000 accepted";
  } catch (const std::invalid_argument& e) {
    EXPECT_TRUE(contains(e.what(), "threads")) << e.what();
  }
  FilterConfigs filters;
  filters.gms.grid_cells = 46341;  // its square overflowed int
  EXPECT_THROW(validate(filters), std::invalid_argument);
  SilhouetteConfig recipe;
  recipe.dilate_px = 100000;
  EXPECT_THROW(validate(recipe), std::invalid_argument);
  SiftConfig sift;
  sift.max_image_pixels = 1000;
  EXPECT_THROW(detectSift(cv::Mat(100, 100, CV_8UC1, cv::Scalar(0)), sift), std::invalid_argument);
}

TEST(Readers, APfmHeaderCannotAskForMoreThanTheFileHolds) {
  const std::string dir = test::temporaryDirectory();
  writeText(dir + "/big.pfm", "Pf\n32768 32768\n-1\n");  // 18 bytes announcing 4 GiB
  try {
    readPfm(dir + "/big.pfm");
    FAIL() << "accepted";
  } catch (const std::exception& e) {
    EXPECT_TRUE(contains(e.what(), "announces")) << e.what();
  }
  writeText(dir + "/nan.pfm", "Pf\n1 1\nnan\n....");
  EXPECT_THROW(readPfm(dir + "/nan.pfm"), std::exception);
}

TEST(Readers, NumbersWithTrailingBytesAreRefused) {
  const std::string dir = test::temporaryDirectory();
  writeText(dir + "/H", std::string("1 0 0\n0 1 0\n0 0 1.5\0garbage\n", 28));
  EXPECT_THROW(readHomography(dir + "/H"), std::exception);
  writeText(dir + "/H10", "1 0 0 0 1 0 0 0 1 1\n");
  EXPECT_THROW(readHomography(dir + "/H10"), std::exception);
  CalibratedView view;
  view.name = "a.png";
  view.camera = PinholeCamera(Eigen::Matrix3d::Identity(), Eigen::Matrix3d::Identity(),
                              Eigen::Vector3d(0, 0, 1));
  writeMiddleburyPar(dir + "/good.txt", {view});
  std::ifstream in(dir + "/good.txt");
  std::string text((std::istreambuf_iterator<char>(in)), {});
  const size_t last_digit = text.find_last_of("0123456789");
  text.insert(last_digit + 1, std::string("\0garbage", 8));
  writeText(dir + "/nul.txt", text);
  try {
    readMiddleburyPar(dir + "/nul.txt");
    FAIL() << "a NUL byte inside a number was accepted";
  } catch (const std::exception& e) {
    EXPECT_TRUE(contains(e.what(), "NUL")) << e.what();
  }
}

TEST(BoundingBox, HugeTranslationsEndInAnErrorNotAnAbort) {
  HullInput input = ring(8);
  std::vector<SilhouetteBounds> bounds;
  for (const cv::Mat& mask : input.masks) bounds.push_back(silhouetteBounds(mask, false));
  for (double t : {1e307, 1e39, 1e20}) {
    std::vector<PinholeCamera> cameras = input.cameras;
    cameras[3] = PinholeCamera(cameras[3].K(), cameras[3].R(), Eigen::Vector3d(0, 0, t));
    try {
      const Box3d box = hullBoundingBox(cameras, bounds);
      // A box may come out (the far view's cone is nearly a ray); carving must then refuse it.
      VisualHull hull(box, HullConfig());
      EXPECT_THROW(hull.addViews(makeHullViews(input.names, cameras, input.masks, HullConfig())),
                   std::invalid_argument)
          << "t = " << t;
    } catch (const std::exception& e) {
      SUCCEED() << e.what();
    }
  }
}

TEST(BoundingBox, ASolveOnAThreadThatEndsLeavesNoGlpkMemory) {
  // The hull node solves on a worker thread. GLPK keeps an environment per thread; under
  // LeakSanitizer (scripts/sanitize.sh) whatever it keeps after the thread ends is a failure.
  const HullInput input = ring(8);
  std::vector<SilhouetteBounds> bounds;
  for (const cv::Mat& mask : input.masks) bounds.push_back(silhouetteBounds(mask, false));
  Box3d box;
  std::thread worker([&] { box = hullBoundingBox(input.cameras, bounds); });
  worker.join();
  EXPECT_TRUE((box.size().array() > 0.0).all());
}

TEST(BoundingBox, DegenerateBoundsEndInAnError) {
  HullInput input = ring(4);
  std::vector<SilhouetteBounds> bounds;
  for (const cv::Mat& mask : input.masks) {
    SilhouetteBounds b = silhouetteBounds(mask, false);
    b.u_max_px = b.u_min_px;  // zero width
    b.v_max_px = b.v_min_px;
    bounds.push_back(b);
  }
  EXPECT_THROW(hullBoundingBox(input.cameras, bounds), HullBoxError);
  bounds[0].u_max_px = bounds[0].u_min_px - 1.0;  // not ordered
  EXPECT_THROW(hullBoundingBox(input.cameras, bounds), std::invalid_argument);
}

TEST(VisualHull, BoxesTheCamerasCannotResolveAreRefused) {
  const HullInput input = ring(8);
  HullConfig config;
  config.max_depth = 6;
  for (double half_edge : {1e39, 1e6}) {  // a voxel wider than the cameras' distance
    Box3d box;
    box.min_W = Eigen::Vector3d::Constant(-half_edge);
    box.max_W = Eigen::Vector3d::Constant(half_edge);
    VisualHull hull(box, config);
    EXPECT_THROW(hull.addViews(makeHullViews(input.names, input.cameras, input.masks, config)),
                 std::invalid_argument)
        << half_edge;
    EXPECT_EQ(hull.views().size(), 0u);  // nothing carved
  }
  Box3d tiny;  // cameras a million box sizes away and more
  tiny.min_W = Eigen::Vector3d::Zero();
  tiny.max_W = Eigen::Vector3d::Constant(1e-300);
  VisualHull hull(tiny, config);
  EXPECT_THROW(hull.addViews(makeHullViews(input.names, input.cameras, input.masks, config)),
               std::invalid_argument);
}

TEST(VisualHull, ABoxBeyondIntVoxelIndicesIsRefused) {
  Box3d earth_centred;  // a 1 m box 6400 km from the origin at depth 10: 6e9 voxels out
  earth_centred.min_W = Eigen::Vector3d(6.4e6, 0, 0);
  earth_centred.max_W = Eigen::Vector3d(6.4e6 + 1, 1, 1);
  HullConfig config;
  config.max_depth = 10;
  EXPECT_THROW(VisualHull(earth_centred, config), std::invalid_argument);
  HullStreamConfig stream;
  stream.box = earth_centred;
  stream.hull = config;
  EXPECT_THROW(validate(stream), std::invalid_argument);
}

TEST(VisualHull, AWorldFrameFarFromItsOriginGivesTheSameHull) {
  // A map frame 100 km from its origin: the local frame keeps single precision's accuracy.
  const HullInput input = ring(8);
  HullConfig config;
  config.max_depth = 6;
  const HullResult near = buildHull(input, config);
  HullInput far = input;
  const Eigen::Vector3d shift(1e5, -2e5, 3e4);
  for (PinholeCamera& camera : far.cameras) {
    camera = PinholeCamera::fromCentre(camera.K(), camera.R(), camera.centre() + shift);
  }
  const HullResult moved = buildHull(far, config);
  const double relative =
      std::abs(moved.hull.stats().occupied_volume_m3 - near.hull.stats().occupied_volume_m3) /
      near.hull.stats().occupied_volume_m3;
  EXPECT_LT(relative, 0.02) << "volumes " << near.hull.stats().occupied_volume_m3 << " and "
                            << moved.hull.stats().occupied_volume_m3;
}

// ---- the command-line program --------------------------------------------------------------

class HostileCommandLine : public test::WrittenSceneSuite {
 protected:
  /// Runs `hull` on the scene with `calib` (the scene's own by default) and extra arguments.
  int hull(const std::string& extra, std::string* err, const std::string& calib = "") {
    std::string out;
    const std::string par = calib.empty() ? *scene_ + "/scene_par.txt" : calib;
    return test::runProgram("hull --calib " + par + " --images " + *scene_ + " --silhouettes " +
                                *scene_ + "/masks --max-depth 6 " + extra,
                            &out, err);
  }

  /// The scene's par file with one camera moved: `line` (1-based view) centre z set to `z`.
  std::string parWithCameraAt(double z, bool translation) {
    std::vector<CalibratedView> views = readCalibration(*scene_ + "/scene_par.txt");
    PinholeCamera& camera = views[1].camera;
    if (translation) {
      camera = PinholeCamera(camera.K(), camera.R(), Eigen::Vector3d(0, 0, z));
    } else {
      camera = PinholeCamera::fromCentre(camera.K(), camera.R(), Eigen::Vector3d(0, 0, z));
    }
    const std::string path = test::temporaryDirectory() + "/par.txt";
    writeMiddleburyPar(path, views);
    return path;
  }
};

TEST_F(HostileCommandLine, HugeCoordinatesEndInAClearError) {
  std::string err;
  EXPECT_EQ(hull("--box -0.8,-0.8,-1.3,0.8,0.8,0.9", &err, parWithCameraAt(1e39, false)), 1);
  EXPECT_TRUE(contains(err, "half cube edges")) << err;
  EXPECT_EQ(hull("", &err, parWithCameraAt(1e307, true)), 1) << err;
  EXPECT_EQ(hull("--box -1e39,-1e39,-1e39,1e39,1e39,1e39", &err), 1);
  EXPECT_TRUE(contains(err, "mutual distance")) << err;
  EXPECT_EQ(hull("--box -1e39,-1e39,-1e39,1e39,1e39,1e39 --allow-poor", &err), 1);
  EXPECT_TRUE(contains(err, "too large")) << err;
  EXPECT_EQ(hull("--box 0,0,0,1e-300,1e-300,1e-300", &err), 1);
}

TEST_F(HostileCommandLine, AFarTranslationIsBlamedOnItsOwnView) {
  // Before, the box LP, framed by the far camera, said that the point where the optical axes meet
  // is behind five other views.
  std::string err;
  EXPECT_EQ(hull("", &err, parWithCameraAt(1e30, true)), 1);
  EXPECT_TRUE(contains(err,
                       "view 'view_0001.png': its camera lies 1e+30 from the cameras' median "
                       "centre, more than 1e+06 times their median distance from it ("))
      << err;
  EXPECT_TRUE(contains(err, "): check its translation")) << err;
}

TEST_F(HostileCommandLine, OutOfRangeSettingsAreUsageErrors) {
  std::string err, out;
  EXPECT_EQ(hull("--max-depth 12", &err), 2);
  EXPECT_TRUE(contains(err, "--max-depth must be")) << err;
  EXPECT_EQ(hull("--threads 100000", &err), 2);
  EXPECT_EQ(hull("--views ,", &err), 2);
  const std::string left = *scene_ + "/view_0000.png", right = *scene_ + "/view_0001.png";
  EXPECT_EQ(
      test::runProgram("match " + left + " " + right + " --filter gms --gms-grid-cells 100000",
                       &out, &err),
      2);
  EXPECT_EQ(test::runProgram("match " + left + " " + right + " --filter +gsc", &out, &err), 2);
  EXPECT_EQ(test::runProgram("match " + left + " " + right + " --filter epipolar", &out, &err), 2);
  EXPECT_EQ(test::runProgram("bag --calib " + *scene_ + "/scene_par.txt --images " + *scene_ +
                                 " --silhouettes " + *scene_ + "/masks --out " +
                                 test::temporaryDirectory() + "/x.bag --rate 1e300",
                             &out, &err),
            2);
}

TEST_F(HostileCommandLine, AViewOfAnotherSizeIsRefused) {
  const std::string dir = test::temporaryDirectory();
  std::string out, err;
  ASSERT_EQ(test::runCommand("cp -r " + *scene_ + "/. " + dir, &out, &err), 0);
  cv::Mat big;
  cv::resize(cv::imread(dir + "/view_0003.png"), big, cv::Size(640, 480));
  cv::imwrite(dir + "/view_0003.png", big);
  EXPECT_EQ(test::runProgram("hull --calib " + dir + "/scene_par.txt --images " + dir +
                                 " --threshold 0.1 --max-depth 6",
                             &out, &err),
            1);
  EXPECT_TRUE(contains(err, "image size differs")) << err;
}

TEST_F(HostileCommandLine, TheReproducersOfSharedReproEndInClearErrors) {
  const std::string repro = std::string(SIFT_HULL_SOURCE_DIR) + "/../shared/repro";
  if (!test::fileExists(repro + "/README.md")) GTEST_SKIP() << repro << " not found";
  std::string err, out;
  EXPECT_EQ(hull("--box -0.8,-0.8,-1.3,0.8,0.8,0.9", &err, repro + "/par_c_1e39.txt"), 1) << err;
  EXPECT_EQ(hull("", &err, repro + "/par_t_1e307.txt"), 1) << err;
  EXPECT_EQ(test::runProgram("match " + *scene_ + "/view_0000.png " + *scene_ +
                                 "/view_0001.png --filter gsc --gt-disparity " + repro +
                                 "/pfm_4GiB_header.pfm",
                             &out, &err),
            1);
  EXPECT_TRUE(contains(err, "announces")) << err;
}

}  // namespace
}  // namespace sift_hull
