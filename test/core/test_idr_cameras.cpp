// IDR / NeuS / VolSDF camera files (io/idr.h): the writer read back, numpy's own archives
// (test/data/idr, made by make_fixtures.py), the image/ convention, the dispatch of --calib and
// the refusals of malformed files.

#include <gtest/gtest.h>

#include <Eigen/Dense>
#include <cstdio>
#include <fstream>
#include <functional>
#include <iterator>
#include <opencv2/core.hpp>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>
#include <string>
#include <vector>

#include "common/test_data.h"
#include "sift_hull/io/calibration.h"
#include "sift_hull/io/idr.h"
#include "sift_hull/io/npz.h"
#include "sift_hull/synthetic/scene.h"

namespace sift_hull {
namespace {

const std::string kFixtures = std::string(SIFT_HULL_SOURCE_DIR) + "/test/data/idr";

std::string slurp(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  return std::string(std::istreambuf_iterator<char>(in), {});
}

/// Empty files `count` named by a zero-padded index of `digits` digits ("000000.png").
void makeImages(const std::string& directory, int count, int digits) {
  ASSERT_EQ(::system(("mkdir -p " + directory).c_str()), 0);
  for (int i = 0; i < count; ++i) {
    char name[32];
    std::snprintf(name, sizeof(name), "%0*d.png", digits, i);
    std::ofstream(directory + "/" + name);
  }
}

std::string errorOf(const std::function<void()>& read) {
  try {
    read();
  } catch (const ParseError& e) {
    return e.what();
  }
  return "no error";
}

Eigen::Matrix4d scaleMat(const Eigen::Vector3d& centre, double radius) {
  Eigen::Matrix4d S = Eigen::Matrix4d::Identity();
  S.topLeftCorner<3, 3>() *= radius;
  S.topRightCorner<3, 1>() = centre;
  return S;
}

/// Points around `centre` within `radius`.
std::vector<Eigen::Vector3d> samplePoints(const Eigen::Vector3d& centre, double radius) {
  std::vector<Eigen::Vector3d> points;
  for (int i = 0; i < 27; ++i) {
    const Eigen::Vector3d offset(i % 3 - 1.0, (i / 3) % 3 - 1.0, i / 9 - 1.0);
    points.push_back(centre + 0.6 * radius * offset);
  }
  return points;
}

/// Every view projects every point to the same pixel in both sets (within `tolerance_px`), in
/// front of both cameras.
void expectSameProjections(const std::vector<CalibratedView>& a,
                           const std::vector<CalibratedView>& b,
                           const std::vector<Eigen::Vector3d>& points, double tolerance_px) {
  ASSERT_EQ(a.size(), b.size());
  for (size_t i = 0; i < a.size(); ++i) {
    EXPECT_EQ(a[i].camera.improper(), b[i].camera.improper()) << i;
    for (const Eigen::Vector3d& X : points) {
      EXPECT_GT(a[i].camera.depth(X), 0.0) << i;
      EXPECT_GT(b[i].camera.depth(X), 0.0) << i;
      EXPECT_LT((a[i].camera.project(X) - b[i].camera.project(X)).norm(), tolerance_px)
          << "view " << i << " point " << X.transpose();
    }
  }
}

class IdrCamerasTest : public ::testing::Test {
 protected:
  void SetUp() override { dir_ = test::temporaryDirectory(); }
  std::string write(const std::string& name, const std::string& bytes) {
    std::ofstream(dir_ + "/" + name, std::ios::binary) << bytes;
    return dir_ + "/" + name;
  }
  /// An archive of the given entries, read with `images` images named 0.png, 1.png, ...
  std::string npzError(const std::vector<std::pair<std::string, std::string>>& entries,
                       size_t images = 2) {
    const std::string path = dir_ + "/cameras.npz";
    writeNpz(path, entries);
    std::vector<std::string> names;
    for (size_t i = 0; i < images; ++i) names.push_back(std::to_string(i) + ".png");
    return errorOf([&] { idrViews(readIdrCameraMatrices(path), names, path); });
  }
  std::string dir_;
};

/// Two cameras 4 units from the origin, looking at it.
std::vector<std::pair<std::string, std::string>> twoGoodViews() {
  Eigen::Matrix3d K;
  K << 300, 0, 159.5, 0, 300, 119.5, 0, 0, 1;
  std::vector<std::pair<std::string, std::string>> entries;
  for (int i = 0; i < 2; ++i) {
    const Eigen::Matrix3d R =
        Eigen::AngleAxisd(i * 0.5, Eigen::Vector3d::UnitY()).toRotationMatrix().transpose();
    const Eigen::Vector3d t(0, 0, 4);
    Eigen::Matrix4d W = Eigen::Matrix4d::Identity();
    W.topLeftCorner<3, 3>() = K * R;
    W.topRightCorner<3, 1>() = K * t;
    entries.emplace_back("world_mat_" + std::to_string(i) + ".npy", npyBytes(W));
  }
  return entries;
}

TEST_F(IdrCamerasTest, SceneCamerasRoundTripThroughTheWriter) {
  SceneConfig config = test::smallRing();
  config.layout = "sphere";
  const Shape shape = Shape::byName(config.shape);
  const std::vector<CalibratedView> views = sceneCameras(config, shape);
  const Eigen::Matrix4d S = scaleMat(shape.boundingCentre(), shape.boundingRadius());
  const std::string npz = dir_ + "/cameras.npz";
  writeIdrCameras(npz, views, S);
  makeImages(dir_ + "/image", config.views, 6);
  makeImages(dir_ + "/mask", config.views, 3);  // DTU's: the names come from image/ only

  const std::vector<CalibratedView> read = readCalibration(npz);
  ASSERT_EQ(read.size(), views.size());
  EXPECT_EQ(read[0].name, "000000.png");
  EXPECT_EQ(read[11].name, "000011.png");
  EXPECT_EQ(read[3].camera_model, "IDR");
  EXPECT_EQ(read[3].source, npz + " (world_mat_3.npy (000003.png))");
  for (const CalibratedView& view : read) {
    EXPECT_FALSE(view.camera.improper());
    EXPECT_GT(view.camera.K()(0, 0), 0.0);
    EXPECT_GT(view.camera.K()(1, 1), 0.0);
    EXPECT_DOUBLE_EQ(view.camera.K()(2, 2), 1.0);
  }
  expectSameProjections(views, read, samplePoints(shape.boundingCentre(), shape.boundingRadius()),
                        1e-6);
  // The directory, an explicit --images directory and calibrationFormat.
  expectSameProjections(views, readCalibration(dir_),
                        samplePoints(shape.boundingCentre(), shape.boundingRadius()), 1e-6);
  EXPECT_EQ(readCalibrationWithImages(npz, dir_ + "/image")[5].name, "000005.png");
  EXPECT_EQ(calibrationFormat(npz), "IDR cameras.npz");
  EXPECT_EQ(calibrationFormat(dir_), "IDR cameras.npz");
  EXPECT_EQ(idrCamerasFile(dir_), npz);

  const std::optional<Box3d> box = idrObjectBox(dir_);
  ASSERT_TRUE(box);
  const Eigen::Vector3d half = Eigen::Vector3d::Constant(shape.boundingRadius());
  EXPECT_TRUE(box->min_W.isApprox(shape.boundingCentre() - half, 1e-12));
  EXPECT_TRUE(box->max_W.isApprox(shape.boundingCentre() + half, 1e-12));
}

TEST_F(IdrCamerasTest, MirroredWorldGivesImproperCamerasOrientedByTheObject) {
  SceneConfig config = test::smallRing();
  const Shape shape = Shape::byName("sphere");
  std::vector<CalibratedView> views = sceneCameras(config, shape);
  // The world mirrored (x negated): P' = P diag(-1, 1, 1) sees mirror * X where P saw X, with a
  // left block of det < 0. Written by hand, as PinholeCamera's constructor takes rotations only.
  const Eigen::Matrix3d mirror = Eigen::Vector3d(-1, 1, 1).asDiagonal();
  std::vector<std::pair<std::string, std::string>> entries;
  for (size_t i = 0; i < views.size(); ++i) {
    Eigen::Matrix4d W = Eigen::Matrix4d::Identity();
    W.topRows<3>() = views[i].camera.projectionMatrix();
    W.topLeftCorner<3, 3>() = W.topLeftCorner<3, 3>() * mirror;
    if (i % 2) W.topRows<3>() *= -3.0;  // a P's scale and sign are free
    entries.emplace_back("world_mat_" + std::to_string(i) + ".npy", npyBytes(W));
  }
  entries.emplace_back("scale_mat_0.npy",
                       npyBytes(scaleMat(mirror * shape.boundingCentre(), shape.boundingRadius())));
  const std::string npz = dir_ + "/cameras.npz";
  writeNpz(npz, entries);
  makeImages(dir_ + "/image", config.views, 6);
  const std::vector<CalibratedView> read = readCalibration(npz);
  ASSERT_EQ(read.size(), views.size());
  for (size_t i = 0; i < read.size(); ++i) {
    EXPECT_TRUE(read[i].camera.improper()) << i;
    for (const Eigen::Vector3d& X : samplePoints(shape.boundingCentre(), 0.5)) {
      EXPECT_GT(read[i].camera.depth(mirror * X), 0.0);
      EXPECT_LT((read[i].camera.project(mirror * X) - views[i].camera.project(X)).norm(), 1e-6);
    }
  }
}

TEST_F(IdrCamerasTest, NumpyArchivesStoredDeflatedAndFloat32) {
  // The projection list holds the same P (scaled by -2.5 for view 1, as world_mat_1).
  const std::vector<CalibratedView> list = readCalibration(kFixtures + "/cameras.txt");
  const Eigen::Vector3d centre(0.1, -0.2, 0.3);
  const std::vector<std::string> names = {"a.png", "b.png", "c.png"};
  const std::string deflated = kFixtures + "/cameras_deflated.npz";
  const IdrCameras matrices = readIdrCameraMatrices(deflated);
  ASSERT_EQ(matrices.world_mats.size(), 3u);
  ASSERT_TRUE(matrices.scale_mat);
  // The same numbers as the projection list's, world_mat_1 stored in Fortran order.
  std::ifstream text(kFixtures + "/cameras.txt");
  std::string comment;
  std::getline(text, comment);
  for (int i = 0; i < 3; ++i) {
    for (int k = 0; k < 12; ++k) {
      double value;
      ASSERT_TRUE(text >> value);
      EXPECT_EQ(matrices.world_mats[i](k / 4, k % 4), value) << i << " " << k;
    }
    EXPECT_EQ(matrices.world_mats[i].row(3), Eigen::RowVector4d(0, 0, 0, 1));
  }
  // The same archive read from memory.
  const IdrCameras in_memory = parseIdrCameraMatrices(slurp(deflated), "memory.npz");
  ASSERT_EQ(in_memory.world_mats.size(), 3u);
  for (int i = 0; i < 3; ++i) EXPECT_EQ(in_memory.world_mats[i], matrices.world_mats[i]);
  EXPECT_EQ(*in_memory.scale_mat, *matrices.scale_mat);
  const std::vector<CalibratedView> views = idrViews(matrices, names, deflated);
  expectSameProjections(list, views, samplePoints(centre, 1.5), 1e-9);
  Eigen::Matrix3d K;
  K << 600, 0, 319.5, 0, 610, 239.5, 0, 0, 1;
  for (const CalibratedView& view : views) {
    EXPECT_TRUE(view.camera.K().isApprox(K, 1e-12)) << view.camera.K();
    EXPECT_NEAR((view.camera.centre() - centre).norm(), 4.0, 1e-9);
  }
  const std::optional<Box3d> box = idrObjectBox(deflated);
  ASSERT_TRUE(box);
  EXPECT_TRUE(box->min_W.isApprox(centre - Eigen::Vector3d::Constant(1.5), 1e-12));
  EXPECT_TRUE(box->max_W.isApprox(centre + Eigen::Vector3d::Constant(1.5), 1e-12));

  const std::string float32 = kFixtures + "/cameras_float32.npz";
  expectSameProjections(views, idrViews(readIdrCameraMatrices(float32), names, float32),
                        samplePoints(centre, 1.5), 1e-3);
}

TEST_F(IdrCamerasTest, DirectoryDispatchPrefersCamerasNpzAndYieldsToColmapAndNerf) {
  writeNpz(dir_ + "/cameras_sphere.npz", twoGoodViews());
  makeImages(dir_ + "/image", 2, 6);
  EXPECT_EQ(idrCamerasFile(dir_), dir_ + "/cameras_sphere.npz");
  EXPECT_EQ(readCalibration(dir_).size(), 2u);
  EXPECT_EQ(calibrationFormat(dir_ + "/cameras_sphere.npz"), "IDR cameras.npz");
  // cameras.npz first: this one has three views.
  auto three = twoGoodViews();
  three.push_back({"world_mat_2.npy", three[0].second});
  writeNpz(dir_ + "/cameras.npz", three);
  makeImages(dir_ + "/image", 3, 6);
  EXPECT_EQ(idrCamerasFile(dir_), dir_ + "/cameras.npz");
  EXPECT_EQ(readCalibration(dir_).size(), 3u);
  // An image directory of its own.
  makeImages(dir_ + "/other", 3, 2);
  EXPECT_EQ(readCalibrationWithImages(dir_, dir_ + "/other")[2].name, "02.png");
  // A COLMAP model beside it wins.
  write("cameras.txt", "1 PINHOLE 64 48 50 50 32 24\n");
  write("images.txt", "");
  EXPECT_EQ(idrCamerasFile(dir_), "");
  EXPECT_EQ(calibrationFormat(dir_), "COLMAP text (cameras.txt, images.txt)");
}

TEST_F(IdrCamerasTest, ImageCountsMustMatchTheCameras) {
  const std::string npz = dir_ + "/cameras.npz";
  writeNpz(npz, twoGoodViews());
  makeImages(dir_ + "/image", 3, 6);
  EXPECT_EQ(errorOf([&] { readCalibration(npz); }),
            npz + ": holds 2 cameras but there are 3 images in " + dir_ +
                "/image (view I is the I-th image by name)");
  makeImages(dir_ + "/one", 1, 6);
  EXPECT_EQ(errorOf([&] { readCalibrationWithImages(npz, dir_ + "/one"); }),
            npz + ": holds 2 cameras but there are 1 images in " + dir_ +
                "/one (view I is the I-th image by name)");
  EXPECT_EQ(
      errorOf([&] { readCalibrationWithImages(npz, dir_ + "/none"); }),
      npz + ": the views are the images of " + dir_ + "/none: cannot read the image directory");
  EXPECT_EQ(npzError(twoGoodViews(), 3),
            npz + ": holds 2 cameras (world_mat_0 to world_mat_1) but there are 3 images");
}

TEST_F(IdrCamerasTest, MalformedArchivesAreRefusedNamingFileAndReason) {
  const std::string npz = dir_ + "/cameras.npz";
  const auto good = twoGoodViews();
  EXPECT_EQ(npzError(good), "no error");
  // Not a zip, or a zip cut short (its directory lost).
  EXPECT_EQ(errorOf([&] { readIdrCameraMatrices(write("text.npz", "hello")); }),
            dir_ + "/text.npz: not a zip archive (an .npz file), or it cannot be read");
  writeNpz(npz, good);
  const std::string bytes = slurp(npz);
  const std::string cut = write("cut.npz", bytes.substr(0, bytes.size() / 2));
  EXPECT_EQ(errorOf([&] { readIdrCameraMatrices(cut); }),
            cut + ": not a zip archive (an .npz file), or it cannot be read");
  EXPECT_EQ(errorOf([&] { parseIdrCameraMatrices(bytes.substr(0, bytes.size() / 2), "m.npz"); }),
            "m.npz: not a zip archive (an .npz file), or it cannot be read");
  // A data byte changed: the CRC no longer matches.
  std::string flipped = bytes;
  flipped[bytes.find("\x93NUMPY") + 200] ^= 0x55;
  const std::string crc = write("crc.npz", flipped);
  EXPECT_EQ(errorOf([&] { readIdrCameraMatrices(crc); }),
            crc + ": world_mat_0.npy: corrupt entry: its CRC-32 does not match its contents");
  EXPECT_EQ(errorOf([&] { parseIdrCameraMatrices(flipped, "m.npz"); }),
            "m.npz: world_mat_0.npy: corrupt entry: its CRC-32 does not match its contents");
  // A deflated entry of numpy's archive damaged.
  std::string deflated = slurp(kFixtures + "/cameras_deflated.npz");
  for (size_t i = 70; i < 90; ++i) deflated[i] = static_cast<char>(0xff);
  const std::string bad_deflate = write("bad_deflate.npz", deflated);
  const std::string message = errorOf([&] { readIdrCameraMatrices(bad_deflate); });
  EXPECT_EQ(message.rfind(bad_deflate + ": world_mat_0.npy: ", 0), 0u) << message;

  const auto with = [&](const std::string& name, const Eigen::MatrixXd& m) {
    auto entries = good;
    for (auto& entry : entries) {
      if (entry.first == name) entry.second = npyBytes(m);
    }
    if (name.rfind("world_mat_", 0) != 0 || name == "world_mat_5.npy") {
      entries.emplace_back(name, npyBytes(m));
    }
    return entries;
  };
  EXPECT_EQ(npzError(with("world_mat_1.npy", Eigen::MatrixXd::Identity(3, 4))),
            npz + ": world_mat_1.npy: array shape (3, 4) is not (4, 4)");
  Eigen::Matrix4d nan = Eigen::Matrix4d::Identity();
  nan(1, 2) = std::nan("");
  EXPECT_EQ(npzError(with("world_mat_0.npy", nan)),
            npz + ": world_mat_0.npy: a value is not finite");
  Eigen::Matrix4d singular = Eigen::Matrix4d::Identity();
  singular(2, 2) = 0.0;
  EXPECT_EQ(npzError(with("world_mat_1.npy", singular)),
            npz + ": world_mat_1.npy (1.png): the left 3x3 block of P is singular");
  Eigen::Matrix4d last_row = Eigen::Matrix4d::Identity();
  last_row(3, 0) = 2.0;
  EXPECT_EQ(npzError(with("world_mat_0.npy", last_row)),
            npz + ": world_mat_0.npy: the last row is 2 0 0 1, not 0 0 0 1");
  EXPECT_EQ(npzError(with("scale_mat_0.npy", Eigen::Matrix4d::Zero())),
            npz + ": scale_mat_0.npy: the last row is 0 0 0 0, not 0 0 0 1");
  // A gap, no world_mat at all, a leading zero, an index beyond the limit.
  EXPECT_EQ(npzError(with("world_mat_5.npy", Eigen::Matrix4d::Identity())),
            npz +
                ": no world_mat_2.npy, though world_mat_5.npy is given: the indices must run "
                "from 0 without a gap");
  EXPECT_EQ(npzError({{"camera_mat_0.npy", npyBytes(Eigen::Matrix4d::Identity())}}),
            npz + ": no world_mat_0.npy entry: not an IDR / NeuS cameras file");
  EXPECT_EQ(npzError({{"world_mat_01.npy", good[0].second}}),
            npz +
                ": world_mat_01.npy: the index has a leading zero (world_mat_0.npy, "
                "world_mat_1.npy, ...)");
  EXPECT_EQ(npzError({{"world_mat_1000000.npy", good[0].second}}),
            npz + ": world_mat_1000000.npy: the index is beyond the limit of 1000000 views");
  // A float16 array, and an entry larger than the limit (checked before it is read).
  std::string half = good[0].second;
  half.replace(half.find("<f8"), 3, "<f2");
  EXPECT_EQ(npzError({{"world_mat_0.npy", half}}),
            npz +
                ": world_mat_0.npy: dtype '<f2' is not supported: expected little-endian "
                "float64 or float32 ('<f8' or '<f4')");
  EXPECT_EQ(npzError({{"world_mat_0.npy", std::string((1 << 20) + 1, 'x')}}),
            npz +
                ": world_mat_0.npy: the entry holds 1048577 bytes, more than the limit of "
                "1048576");
  EXPECT_EQ(npzError({{"world_mat_0.npy", good[0].second}, {"world_mat_0.npy", good[0].second}}),
            npz + ": the archive holds the entry 'world_mat_0.npy' twice");
}

TEST_F(IdrCamerasTest, CamerasDisagreeingOnHandednessAreNamed) {
  auto entries = twoGoodViews();
  Eigen::Matrix4d W = Eigen::Matrix4d::Identity();
  Eigen::Matrix3d K;
  K << 300, 0, 159.5, 0, 300, 119.5, 0, 0, 1;
  W.topLeftCorner<3, 3>() = K * Eigen::Vector3d(-1, 1, 1).asDiagonal();  // a mirrored frame
  W.topRightCorner<3, 1>() = K * Eigen::Vector3d(0, 0, 4);
  entries.emplace_back("world_mat_2.npy", npyBytes(W));
  entries.emplace_back("scale_mat_0.npy", npyBytes(scaleMat(Eigen::Vector3d::Zero(), 1.0)));
  EXPECT_EQ(npzError(entries, 3),
            dir_ +
                "/cameras.npz: the cameras cannot be oriented consistently: '2.png' see the "
                "object (scale_mat_0's centre) in front of them only if their world frame is "
                "mirrored while the other cameras' is right-handed; check their world_mat");
}

TEST_F(IdrCamerasTest, DatasetInfoReportsTheObjectBox) {
  writeNpz(dir_ + "/cameras.npz", [] {
    auto entries = twoGoodViews();
    entries.emplace_back("scale_mat_0.npy",
                         npyBytes(scaleMat(Eigen::Vector3d(0.25, 0, -0.5), 0.75)));
    return entries;
  }());
  ASSERT_EQ(::system(("mkdir -p " + dir_ + "/image").c_str()), 0);
  for (const char* name : {"000000.png", "000001.png"}) {
    cv::Mat image(240, 320, CV_8UC3, cv::Scalar::all(0));
    cv::circle(image, {160, 120}, 40, cv::Scalar::all(255), -1);
    ASSERT_TRUE(cv::imwrite(dir_ + "/image/" + name, image));
  }
  std::string out, err;
  ASSERT_EQ(test::runProgram("dataset-info --calib " + dir_, &out, &err), 0) << err;
  EXPECT_NE(out.find("format: IDR cameras.npz, camera model IDR, no distortion"), std::string::npos)
      << out;
  EXPECT_NE(out.find("IDR object box (scale_mat_0's unit sphere): [-0.5,-0.75,-1.25] .. "
                     "[1.0,0.75,0.25] (--box -0.5,-0.75,-1.25,1,0.75,0.25)"),
            std::string::npos)
      << out;
  ASSERT_EQ(test::runProgram("dataset-info --json --calib " + dir_ + "/cameras.npz", &out, &err), 0)
      << err;
  EXPECT_NE(out.find("\"box_option\": \"-0.5,-0.75,-1.25,1,0.75,0.25\""), std::string::npos) << out;
}

}  // namespace
}  // namespace sift_hull
