// NeRF / instant-ngp transforms.json (io/nerf.h), read through readCalibration as --calib does.
#include <gtest/gtest.h>

#include <cmath>
#include <fstream>
#include <opencv2/core.hpp>
#include <opencv2/imgcodecs.hpp>

#include "common/test_data.h"
#include "sift_hull/io/calibration.h"
#include "sift_hull/io/nerf.h"
#include "sift_hull/synthetic/scene.h"

namespace sift_hull {
namespace {

class NerfTransforms : public ::testing::Test {
 protected:
  void SetUp() override { dir_ = test::temporaryDirectory(); }
  std::string write(const std::string& name, const std::string& text) {
    std::ofstream(dir_ + "/" + name) << text;
    return dir_ + "/" + name;
  }
  /// The error readCalibration gives for a transforms.json holding `text`.
  std::string error(const std::string& text) {
    const std::string path = write("transforms.json", text);
    try {
      readCalibration(path);
    } catch (const ParseError& e) {
      return e.what();
    }
    return "no error";
  }
  std::string dir_;
};

/// World points around the origin, where the scene's object is.
std::vector<Eigen::Vector3d> samplePoints() {
  std::vector<Eigen::Vector3d> points;
  for (int i = 0; i < 27; ++i) points.emplace_back(i % 3 - 1.0, i / 3 % 3 - 1.0, i / 9 - 1.0);
  for (Eigen::Vector3d& p : points) p *= 0.4;
  return points;
}

/// One frame at the origin looking along -z (OpenGL's identity pose), moved to z = 4.
const char* kOneFrame = R"({"camera_angle_x": 0.8, "w": 64, "h": 48, "frames": [
  {"file_path": "./r_0", "transform_matrix": [[1,0,0,0],[0,1,0,0],[0,0,1,4],[0,0,0,1]]}]})";

TEST_F(NerfTransforms, WrittenCamerasReadBackToTheSameProjections) {
  SceneConfig config;
  config.views = 6;
  config.layout = "sphere";
  std::vector<CalibratedView> cameras = sceneCameras(config, Shape::byName(config.shape));
  LensDistortion lens;
  lens.k1 = -0.05;
  lens.p2 = 0.001;
  cameras[1].camera = cameras[1].camera.withDistortion(lens);
  const std::string path = dir_ + "/transforms.json";
  writeNerfTransforms(path, cameras, config.width_px, config.height_px);
  const std::vector<CalibratedView> read = readCalibration(path);
  ASSERT_EQ(read.size(), cameras.size());
  EXPECT_EQ(calibrationFormat(path), "NeRF transforms.json");
  for (size_t i = 0; i < read.size(); ++i) {
    EXPECT_EQ(read[i].name, cameras[i].name);
    EXPECT_EQ(read[i].camera_model, "NeRF");
    EXPECT_EQ(read[i].width_px, static_cast<uint64_t>(config.width_px));
    EXPECT_EQ(read[i].height_px, static_cast<uint64_t>(config.height_px));
    for (const Eigen::Vector3d& X : samplePoints()) {
      EXPECT_LT((read[i].camera.project(X) - cameras[i].camera.project(X)).norm(), 1e-9)
          << read[i].name;
    }
  }
  EXPECT_DOUBLE_EQ(read[1].camera.distortion().k1, -0.05);
  EXPECT_DOUBLE_EQ(read[1].camera.distortion().p2, 0.001);
  // A directory holding the file is the same calibration.
  EXPECT_EQ(readCalibration(dir_).size(), cameras.size());
  EXPECT_EQ(calibrationFormat(dir_), "NeRF transforms.json");
}

TEST_F(NerfTransforms, OpenGlAxesAndPixelCentresFollowTheConvention) {
  const std::vector<CalibratedView> views = readCalibration(write("transforms.json", kOneFrame));
  ASSERT_EQ(views.size(), 1u);
  const PinholeCamera& camera = views[0].camera;
  // No cx, cy: the principal point is the image centre; pixel centres are integers here, so the
  // centre of a 64x48 image is (31.5, 23.5).
  const Eigen::Vector2d centre = camera.project(Eigen::Vector3d::Zero());
  EXPECT_NEAR(centre.x(), 31.5, 1e-12);
  EXPECT_NEAR(centre.y(), 23.5, 1e-12);
  EXPECT_GT(camera.depth(Eigen::Vector3d::Zero()), 0.0) << "the camera looks along -z";
  // OpenGL's y is up: a point above the origin is higher in the image (smaller row); +x right.
  EXPECT_LT(camera.project(Eigen::Vector3d(0, 0.1, 0)).y(), centre.y());
  EXPECT_GT(camera.project(Eigen::Vector3d(0.1, 0, 0)).x(), centre.x());
  // camera_angle_x is the full horizontal field of view.
  EXPECT_NEAR(camera.K()(0, 0), 32.0 / std::tan(0.4), 1e-9);
  EXPECT_NEAR(camera.K()(1, 1), camera.K()(0, 0), 1e-12);
  // file_path without an extension, nothing beside it: .png.
  EXPECT_EQ(views[0].name, "r_0.png");
  // instant-ngp's cx = w / 2 is the same centre.
  const std::vector<CalibratedView> explicit_centre = readCalibration(
      write("transforms.json",
            R"({"fl_x": 50, "fl_y": 60, "cx": 32, "cy": 24, "w": 64, "h": 48, "frames": [
  {"file_path": "a.jpg", "transform_matrix": [[1,0,0,0],[0,1,0,0],[0,0,1,4],[0,0,0,1]]}]})"));
  EXPECT_NEAR(explicit_centre[0].camera.K()(0, 2), 31.5, 1e-12);
  EXPECT_NEAR(explicit_centre[0].camera.K()(1, 2), 23.5, 1e-12);
  EXPECT_NEAR(explicit_centre[0].camera.K()(1, 1), 60.0, 1e-12);
}

TEST_F(NerfTransforms, SizeComesFromTheImageAndFramesOverrideTheFile) {
  cv::imwrite(dir_ + "/r_0.jpg", cv::Mat(30, 40, CV_8UC3, cv::Scalar::all(90)));
  const std::vector<CalibratedView> views =
      readCalibration(write("transforms.json",
                            R"({"camera_angle_x": 0.8, "frames": [
  {"file_path": "r_0", "transform_matrix": [[1,0,0,0],[0,1,0,0],[0,0,1,4],[0,0,0,1]]},
  {"file_path": "r_0", "fl_x": 70, "k1": 0.1,
   "transform_matrix": [[1,0,0,0],[0,1,0,0],[0,0,1,5],[0,0,0,1]]}]})"));
  ASSERT_EQ(views.size(), 2u);
  EXPECT_EQ(views[0].name, "r_0.jpg") << "the extension found beside the json";
  EXPECT_EQ(views[0].width_px, 40u);
  EXPECT_EQ(views[0].height_px, 30u);
  EXPECT_NEAR(views[0].camera.K()(0, 0), 20.0 / std::tan(0.4), 1e-9);
  EXPECT_NEAR(views[1].camera.K()(0, 0), 70.0, 1e-12);
  EXPECT_DOUBLE_EQ(views[1].camera.distortion().k1, 0.1);
  EXPECT_TRUE(views[0].camera.distortion().isZero());
}

TEST_F(NerfTransforms, SplitFilesOfADirectoryAreReadInOrder) {
  const auto frame = [](const std::string& name, double z) {
    return R"({"file_path": ")" + name + R"(", "transform_matrix": [[1,0,0,0],[0,1,0,0],[0,0,1,)" +
           std::to_string(z) + R"(],[0,0,0,1]]})";
  };
  const std::string head = R"({"camera_angle_x": 0.8, "w": 64, "h": 48, "frames": [)";
  write("transforms_test.json", head + frame("test/c", 6) + "]}");
  write("transforms_train.json", head + frame("train/a", 4) + "," + frame("train/b", 5) + "]}");
  write("transforms_val.json", head + frame("val/d", 7) + "]}");
  const std::vector<CalibratedView> views = readCalibration(dir_);
  ASSERT_EQ(views.size(), 4u);
  EXPECT_EQ(views[0].name, "train/a.png");
  EXPECT_EQ(views[1].name, "train/b.png");
  EXPECT_EQ(views[2].name, "val/d.png");
  EXPECT_EQ(views[3].name, "test/c.png");
  EXPECT_NEAR(views[3].camera.centre().z(), 6.0, 1e-12);
  // A COLMAP model in the same directory wins: it is what a COLMAP run left there.
  std::ofstream(dir_ + "/cameras.txt") << "# empty\n";
  EXPECT_TRUE(nerfTransformFiles(dir_).empty());
}

TEST_F(NerfTransforms, MalformedFilesNameTheFrameAndTheReason) {
  const std::string good_matrix = R"([[1,0,0,0],[0,1,0,0],[0,0,1,4],[0,0,0,1]])";
  const auto one = [&](const std::string& fields, const std::string& matrix) {
    return R"({"w": 64, "h": 48, "frames": [{"file_path": "a.png", )" + fields +
           R"("transform_matrix": )" + matrix + "}]}";
  };
  EXPECT_NE(error("{\"frames\": [").find("not valid JSON"), std::string::npos);
  EXPECT_NE(error("[1, 2]").find("not a JSON object"), std::string::npos);
  EXPECT_NE(error("{\"fl_x\": 3}").find("no \"frames\" array"), std::string::npos);
  EXPECT_NE(error("{\"frames\": []}").find("\"frames\" is empty"), std::string::npos);
  EXPECT_NE(error(one("", good_matrix)).find("frame 0 (a.png): neither \"fl_x\""),
            std::string::npos);
  EXPECT_NE(error(one("\"fl_x\": -5, ", good_matrix)).find("focal lengths must be positive"),
            std::string::npos);
  EXPECT_NE(error(one("\"camera_angle_x\": 4, ", good_matrix)).find("(0, pi)"), std::string::npos);
  EXPECT_NE(error(one("\"fl_x\": \"50\", ", good_matrix)).find("\"fl_x\" is not a number"),
            std::string::npos);
  EXPECT_NE(error(one("\"fl_x\": 50, ", "[[1,0,0],[0,1,0]]")).find("4 rows (or 3) of 4"),
            std::string::npos);
  EXPECT_NE(error(one("\"fl_x\": 50, ", R"([[1,0,0,0],[0,1,0,0],[0,0,1,4],[0,0,1,1]])"))
                .find("last row is not 0 0 0 1"),
            std::string::npos);
  EXPECT_NE(error(one("\"fl_x\": 50, ", R"([[2,0,0,0],[0,1,0,0],[0,0,1,4],[0,0,0,1]])"))
                .find("rigid transform"),
            std::string::npos);
  EXPECT_NE(error(R"({"fl_x": 50, "frames": [{"file_path": "none.png",
    "transform_matrix": [[1,0,0,0],[0,1,0,0],[0,0,1,4],[0,0,0,1]]}]})")
                .find("no \"w\" and \"h\", and the image cannot be read"),
            std::string::npos);
  EXPECT_NE(error(R"({"w": 0, "h": 48, "fl_x": 5, "frames": [{"file_path": "a.png",
    "transform_matrix": [[1,0,0,0],[0,1,0,0],[0,0,1,4],[0,0,0,1]]}]})")
                .find("must lie in [1, 65536]"),
            std::string::npos);
  EXPECT_NE(error(R"({"w": 64, "h": 48, "fl_x": 5, "frames": [{"transform_matrix": []}]})")
                .find("frame 0: no \"file_path\" string"),
            std::string::npos);
  // Every error names the file.
  EXPECT_NE(error("{}").find(dir_ + "/transforms.json"), std::string::npos);
}

}  // namespace
}  // namespace sift_hull
