#include <gtest/gtest.h>
#include <sys/resource.h>
#include <unistd.h>

#include <Eigen/Geometry>
#include <cmath>
#include <cstdlib>
#include <cstring>
#include <fstream>
#include <functional>
#include <iterator>
#include <opencv2/imgcodecs.hpp>
#include <optional>
#include <sstream>

#include "common/test_data.h"
#include "sift_hull/io/calibration.h"
#include "sift_hull/io/colmap.h"
#include "sift_hull/io/images.h"
#include "sift_hull/io/view_list.h"

namespace sift_hull {
namespace {

struct Image {
  uint32_t id;
  Eigen::Quaterniond q;
  Eigen::Vector3d t;
  uint32_t camera_id;
  std::string name;
};

// Camera 1: PINHOLE 640x480; camera 2: OPENCV with distortion. Images listed out of name order.
const std::vector<Image> kImages = {
    {7,
     Eigen::Quaterniond(Eigen::AngleAxisd(0.3, Eigen::Vector3d(0, 1, 0))),
     {0.1, -0.2, 2.0},
     1,
     "b.png"},
    {3,
     Eigen::Quaterniond(Eigen::AngleAxisd(-0.5, Eigen::Vector3d(1, 1, 0).normalized())),
     {-0.3, 0.0, 3.0},
     2,
     "a.png"},
    {9, Eigen::Quaterniond::Identity(), {0.0, 0.0, 2.5}, 1, "c.png"}};

class ColmapModel : public ::testing::Test {
 protected:
  void SetUp() override { dir_ = test::temporaryDirectory(); }

  void writeFile(const std::string& name, const std::string& bytes) {
    std::ofstream(dir_ + "/" + name, std::ios::binary) << bytes;
  }
  static std::string imageLine(const Image& image) {
    std::ostringstream line;
    line.precision(17);
    line << image.id << ' ' << image.q.w() << ' ' << image.q.x() << ' ' << image.q.y() << ' '
         << image.q.z() << ' ' << image.t.x() << ' ' << image.t.y() << ' ' << image.t.z() << ' '
         << image.camera_id << ' ' << image.name << '\n';
    return line.str();
  }
  void writeText(const std::string& cameras = kCamerasText) {
    writeFile("cameras.txt", cameras);
    std::string images = "# Image list with two lines of data per image:\n";
    for (const Image& image : kImages) images += imageLine(image) + "10.5 20.5 -1 30 40 5\n";
    images.back() = '\n';
    writeFile("images.txt", images);
  }

  template <typename T>
  static void put(std::string* out, T value) {
    char raw[sizeof(T)];
    std::memcpy(raw, &value, sizeof(T));
    out->append(raw, sizeof(T));
  }
  static std::string camerasBin(int model_2 = 4, std::vector<double> params_2 = kOpencvParams) {
    std::string b;
    put<uint64_t>(&b, 2);
    put<int32_t>(&b, 1);
    put<int32_t>(&b, 1);
    put<uint64_t>(&b, 640);
    put<uint64_t>(&b, 480);
    for (double p : {500.0, 510.0, 320.5, 240.5}) put(&b, p);
    put<int32_t>(&b, 2);
    put<int32_t>(&b, model_2);
    put<uint64_t>(&b, 800);
    put<uint64_t>(&b, 600);
    for (double p : params_2) put(&b, p);
    return b;
  }
  static std::string imagesBin(uint32_t camera_of_first = 1) {
    std::string b;
    put<uint64_t>(&b, kImages.size());
    for (const Image& image : kImages) {
      put<uint32_t>(&b, image.id);
      for (double v : {image.q.w(), image.q.x(), image.q.y(), image.q.z()}) put(&b, v);
      for (int k = 0; k < 3; ++k) put(&b, image.t[k]);
      put<uint32_t>(&b, &image == &kImages[0] ? camera_of_first : image.camera_id);
      b += image.name;
      b.push_back('\0');
      put<uint64_t>(&b, 2);
      for (int p = 0; p < 2; ++p) {
        put(&b, 10.0);
        put(&b, 20.0);
        put<uint64_t>(&b, 5);
      }
    }
    return b;
  }
  std::string errorOf() {
    try {
      readColmapModel(dir_);
    } catch (const ParseError& e) {
      return e.what();
    }
    return "no error";
  }

  static const std::string kCamerasText;
  static const std::vector<double> kOpencvParams;
  std::string dir_;
};

const std::string ColmapModel::kCamerasText =
    "# Camera list\n1 PINHOLE 640 480 500 510 320.5 240.5\n"
    "2 OPENCV 800 600 700 700 400 300 -0.1 0.01 0.001 -0.002\n";
const std::vector<double> ColmapModel::kOpencvParams = {700,  700,  400,   300,
                                                        -0.1, 0.01, 0.001, -0.002};

void expectKnownCameras(const std::vector<CalibratedView>& views) {
  ASSERT_EQ(views.size(), 3u);
  EXPECT_EQ(views[0].name, "a.png");
  EXPECT_EQ(views[1].name, "b.png");
  EXPECT_EQ(views[2].name, "c.png");
  Eigen::Matrix3d K1, K2;
  K1 << 500, 0, 320, 0, 510, 240, 0, 0, 1;  // COLMAP's corner origin moved to the pixel centre
  K2 << 700, 0, 399.5, 0, 700, 299.5, 0, 0, 1;
  EXPECT_TRUE(views[0].camera.K().isApprox(K2, 1e-12));
  EXPECT_TRUE(views[1].camera.K().isApprox(K1, 1e-12));
  EXPECT_TRUE(views[1].camera.R().isApprox(kImages[0].q.toRotationMatrix(), 1e-12));
  EXPECT_TRUE(views[0].camera.R().isApprox(kImages[1].q.toRotationMatrix(), 1e-12));
  EXPECT_TRUE(views[1].camera.t().isApprox(kImages[0].t, 1e-12));
  EXPECT_TRUE(views[2].camera.t().isApprox(kImages[2].t, 1e-12));
  EXPECT_EQ(views[1].camera_model, "PINHOLE");
  EXPECT_EQ(views[0].camera_model, "OPENCV");
  EXPECT_TRUE(views[1].camera.distortion().isZero());
  EXPECT_DOUBLE_EQ(views[0].camera.distortion().k1, -0.1);
  EXPECT_DOUBLE_EQ(views[0].camera.distortion().k2, 0.01);
  EXPECT_DOUBLE_EQ(views[0].camera.distortion().p1, 0.001);
  EXPECT_DOUBLE_EQ(views[0].camera.distortion().p2, -0.002);
  EXPECT_DOUBLE_EQ(views[0].camera.distortion().k3, 0.0);
}

TEST_F(ColmapModel, TextModelGivesTheKnownCameras) {
  writeText();
  expectKnownCameras(readColmapModel(dir_));
  expectKnownCameras(readCalibration(dir_));
  EXPECT_EQ(calibrationFormat(dir_), "COLMAP text (cameras.txt, images.txt)");
}

TEST_F(ColmapModel, BinaryModelGivesTheSameCameras) {
  writeFile("cameras.bin", camerasBin());
  writeFile("images.bin", imagesBin());
  expectKnownCameras(readColmapModel(dir_));
  EXPECT_EQ(calibrationFormat(dir_), "COLMAP binary (cameras.bin, images.bin)");
}

TEST_F(ColmapModel, EmptyPointLinesAndEveryModelRead) {
  writeFile("cameras.txt",
            "1 SIMPLE_PINHOLE 640 480 500 320 240\n2 SIMPLE_RADIAL 640 480 500 320 240 0.1\n"
            "3 RADIAL 640 480 500 320 240 0.1 0.2\n"
            "4 FULL_OPENCV 640 480 500 501 320 240 0.1 0.2 0.3 0.4 0.5 0.06 0.07 0.08\n"
            "5 OPENCV_FISHEYE 640 480 500 500 320 240 0.05 -0.01 0.002 -0.0004\n");
  writeFile("images.txt",
            "1 1 0 0 0 0 0 2 1 w.png\n\n2 1 0 0 0 0 0 2 2 x.png\n\n3 1 0 0 0 0 0 2 3 y.png\n\n"
            "4 1.005 0 0 0 0 0 2 4 z.png\n\n5 1 0 0 0 0 0 2 5 zz.png\n");
  const auto views = readColmapModel(dir_);
  ASSERT_EQ(views.size(), 5u);
  EXPECT_EQ(views[4].name, "zz.png");                 // views come sorted by name
  EXPECT_TRUE(views[4].camera.distortion().fisheye);  // OpenCV's fisheye: k1..k4
  EXPECT_DOUBLE_EQ(views[4].camera.distortion().k4, -0.0004);
  EXPECT_DOUBLE_EQ(views[0].camera.K()(1, 1), 500.0);
  EXPECT_DOUBLE_EQ(views[1].camera.distortion().k1, 0.1);
  EXPECT_DOUBLE_EQ(views[2].camera.distortion().k2, 0.2);
  EXPECT_DOUBLE_EQ(views[3].camera.distortion().k3, 0.5);
  EXPECT_DOUBLE_EQ(views[3].camera.distortion().k4, 0.06);  // rational: OpenCV's k4, k5, k6
  EXPECT_DOUBLE_EQ(views[3].camera.distortion().k6, 0.08);
  EXPECT_DOUBLE_EQ(views[3].camera.K()(1, 1), 501.0);
  EXPECT_TRUE(views[3].camera.R().isApprox(Eigen::Matrix3d::Identity()));  // q normalised
  EXPECT_EQ(views[3].width_px, 640u);  // the camera's WIDTH x HEIGHT and where it is written
  EXPECT_EQ(views[3].height_px, 480u);
  EXPECT_EQ(views[3].size_source, dir_ + "/cameras.txt:4");
}

TEST_F(ColmapModel, TextErrorsNameFileAndLine) {
  const std::string cameras = dir_ + "/cameras.txt";
  const std::string images = dir_ + "/images.txt";
  EXPECT_EQ(errorOf(), dir_ +
                           ": not a COLMAP sparse model: expected cameras.txt and images.txt, or "
                           "cameras.bin and images.bin");
  writeText("# c\n1 FOV 640 480 1 1 1 1 0\n");
  EXPECT_EQ(errorOf(), cameras +
                           ":2: camera model FOV is not supported (SIMPLE_PINHOLE, "
                           "PINHOLE, SIMPLE_RADIAL, RADIAL, OPENCV, OPENCV_FISHEYE, FULL_OPENCV "
                           "are)");
  writeText("1 WEIRD 640 480 1 1 1\n");
  EXPECT_EQ(errorOf(), cameras + ":1: unknown camera model 'WEIRD'");
  writeText("1 PINHOLE 640 480 500 500 320\n");
  EXPECT_EQ(errorOf(), cameras + ":1: camera model PINHOLE has 4 parameters, found 3");
  writeText("1 PINHOLE 640 480 500 nan 320 240\n");
  EXPECT_EQ(errorOf(), cameras + ":1: 'nan' is not finite");
  writeText("1 PINHOLE 640 480 500 500 320 240\n1 PINHOLE 640 480 500 500 320 240\n");
  EXPECT_EQ(errorOf(), cameras + ":2: camera 1 given twice");
  writeText("1 PINHOLE 640 480 500 500 320 240\n");  // images use camera 2
  EXPECT_EQ(errorOf(), images +
                           ":4: image 'a.png' names camera 2, which the cameras file does "
                           "not hold");
  writeText();
  writeFile("images.txt", "1 0 0 0 0 0 0 2 1 a.png\n");
  EXPECT_EQ(errorOf(), images +
                           ":1: the quaternion (0, 0, 0, 0) is not of unit length: its norm is 0 "
                           "(1 to within 0.01 is normalised)");
  writeFile("images.txt", "1 1 0 0 0 0 0 2 1\n");
  EXPECT_EQ(errorOf(),
            images + ":1: expected IMAGE_ID QW QX QY QZ TX TY TZ CAMERA_ID NAME, found 9 fields");
  writeFile("images.txt", "1 1 0 0 0 0 inf 2 1 a.png\n");
  EXPECT_EQ(errorOf(), images + ":1: 'inf' is not finite");
}

TEST_F(ColmapModel, BinaryErrorsNameTheFile) {
  const std::string cameras = dir_ + "/cameras.bin";
  const std::string images = dir_ + "/images.bin";
  writeFile("images.bin", imagesBin());
  const std::string good = camerasBin();
  writeFile("cameras.bin", good.substr(0, good.size() - 3));
  EXPECT_EQ(errorOf(), cameras +
                           ": truncated: camera parameters at byte 88 runs past the end of the "
                           "file");
  std::string huge = good;
  const uint64_t count = 1ull << 40;
  std::memcpy(&huge[0], &count, 8);
  writeFile("cameras.bin", huge);
  EXPECT_EQ(errorOf(), cameras +
                           ": the file announces 1099511627776 cameras, more than the limit "
                           "of 1000000");
  std::memcpy(&huge[0], "\x05\0\0\0\0\0\0\0", 8);
  writeFile("cameras.bin", huge);
  EXPECT_EQ(errorOf(), cameras +
                           ": the file announces 5 cameras but has only 144 bytes left at "
                           "byte 8");
  writeFile("cameras.bin", camerasBin(7));
  EXPECT_EQ(errorOf(), cameras +
                           ": camera 2 at byte 64: camera model FOV is not "
                           "supported (SIMPLE_PINHOLE, PINHOLE, SIMPLE_RADIAL, RADIAL, "
                           "OPENCV, OPENCV_FISHEYE, FULL_OPENCV are)");
  writeFile("cameras.bin", camerasBin(42));
  EXPECT_EQ(errorOf(), cameras + ": camera 2 at byte 64: unknown camera model id 42");
  writeFile("cameras.bin", camerasBin(4, {700, 700, 400, 300, std::nan(""), 0, 0, 0}));
  EXPECT_EQ(errorOf(), cameras + ": camera 2 at byte 64: a camera parameter is not finite");
  writeFile("cameras.bin", good + "x");
  EXPECT_EQ(errorOf(), cameras + ": 1 bytes after the last camera");
  writeFile("cameras.bin", good);
  writeFile("images.bin", imagesBin(17));
  EXPECT_EQ(errorOf(), images +
                           ": image 7 at byte 8: image 'b.png' names camera 17, which the "
                           "cameras file does not hold");
  const std::string good_images = imagesBin();
  writeFile("images.bin", good_images.substr(0, 90));
  EXPECT_EQ(errorOf(),
            images + ": the file announces 3 images but has only 82 bytes left at byte 8");
  writeFile("images.bin", good_images.substr(0, good_images.size() - 10));
  EXPECT_EQ(errorOf().find(images + ": the file announces 2 points but has only"), 0u) << errorOf();
  writeFile("images.bin", good_images.substr(0, 8 + 4 + 56 + 4 + 3) + std::string(200, 'x'));
  EXPECT_EQ(errorOf().find(images + ": truncated: an image name at byte "), 0u) << errorOf();
  std::string many_points = good_images;
  const uint64_t points = 1ull << 60;
  std::memcpy(&many_points[8 + 4 + 56 + 4 + 6], &points, 8);
  writeFile("images.bin", many_points);
  EXPECT_NE(errorOf().find(images + ": the file announces 1152921504606846976 points but has"),
            std::string::npos)
      << errorOf();
}

TEST_F(ColmapModel, CamerasProjectThroughTheirDistortion) {
  writeText();
  const std::vector<CalibratedView> views = readColmapModel(dir_);
  const PinholeCamera& camera = views[0].camera;
  ASSERT_TRUE(camera.distorted());
  const Eigen::Vector3d X_W = camera.backProject(Eigen::Vector2d(10.0, 20.0), 2.0);
  const Eigen::Vector2d normalised = camera.toCamera(X_W).hnormalized();
  const Eigen::Vector2d expected =
      (camera.K() * distortNormalised(camera.distortion(), normalised).homogeneous()).hnormalized();
  EXPECT_LT((camera.project(X_W) - expected).norm(), 1e-9);
  EXPECT_LT((camera.project(X_W) - Eigen::Vector2d(10.0, 20.0)).norm(), 1e-8);
}

/// images.txt of eight unit-quaternion images on camera 1, each image line followed by
/// `points_line(i)` (nothing when it returns std::nullopt: the POINTS2D line left out).
std::string eightImages(const std::function<std::optional<std::string>(int)>& points_line) {
  std::string text = "# IMAGE_ID, QW, QX, QY, QZ, TX, TY, TZ, CAMERA_ID, NAME\n";
  for (int i = 0; i < 8; ++i) {
    text += std::to_string(i + 1) + " 1 0 0 0 0.1 0 " + std::to_string(2 + i) + " 1 v" +
            std::to_string(i) + ".png\n";
    const std::optional<std::string> points = points_line(i);
    if (points) text += *points + "\n";
  }
  return text;
}

TEST_F(ColmapModel, EveryImageIsKeptWithOrWithoutItsPointsLine) {
  writeFile("cameras.txt", kCamerasText);
  const std::vector<std::function<std::optional<std::string>(int)>> forms = {
      [](int) { return std::string(); },                         // COLMAP: empty lines
      [](int) { return std::nullopt; },                          // lines left out
      [](int) { return std::string("10.5 20.5 -1 30 40 17"); },  // points
      [](int i) {                                                // the three mixed
        return i % 3 == 0 ? std::optional<std::string>() : std::string(i % 3 == 1 ? "" : "1 2 -1");
      }};
  for (size_t form = 0; form < forms.size(); ++form) {
    writeFile("images.txt", eightImages(forms[form]));
    const std::vector<CalibratedView> views = readColmapModel(dir_);
    ASSERT_EQ(views.size(), 8u) << "form " << form;
    for (int i = 0; i < 8; ++i) {
      EXPECT_EQ(views[i].name, "v" + std::to_string(i) + ".png");
      EXPECT_DOUBLE_EQ(views[i].camera.t().z(), 2.0 + i);
    }
  }
}

TEST_F(ColmapModel, APointsLineThatIsNoneIsRefusedNamingItsLine) {
  writeFile("cameras.txt", kCamerasText);
  const std::string images = dir_ + "/images.txt";
  writeFile("images.txt", "1 1 0 0 0 0 0 2 1 a.png\n1 2 -1 3 4\n");
  EXPECT_EQ(errorOf(), images +
                           ":2: expected the POINTS2D line of the image above (X Y POINT3D_ID per "
                           "point: two numbers and an integer) or the next IMAGE_ID QW QX QY QZ "
                           "TX TY TZ CAMERA_ID NAME; found 5 fields");
  writeFile("images.txt", "1 1 0 0 0 0 0 2 1 a.png\n1 2 0.5\n");  // POINT3D_ID not an integer
  EXPECT_EQ(errorOf().find(images + ":2: expected the POINTS2D line"), 0u) << errorOf();
  writeFile("images.txt", "1 1 0 0 0 0 0 2 1 a.png\n1 2 -1\n3 4 -1\n");  // two points lines
  EXPECT_EQ(errorOf(),
            images + ":3: expected IMAGE_ID QW QX QY QZ TX TY TZ CAMERA_ID NAME, found 3 fields");
}

/// The peak resident memory of the process so far, in kB.
long peakResidentKb() {
  struct rusage usage;
  getrusage(RUSAGE_SELF, &usage);
  return usage.ru_maxrss;
}

TEST_F(ColmapModel, PointsLinesAreReadWithoutKeepingThem) {
  writeFile("cameras.txt", kCamerasText);
  {
    std::ofstream out(dir_ + "/images.txt");
    for (int image = 0; image < 2; ++image) {  // 2 x 1.2 million points, about 40 MB
      out << image + 1 << " 1 0 0 0 0 0 2 1 p" << image << ".png\n";
      for (int p = 0; p < 1200000; ++p) out << 1000.25 + p % 997 << " 500.125 " << p << ' ';
      out << "\n";
    }
  }
  const long before_kb = peakResidentKb();
  const std::vector<CalibratedView> views = readColmapModel(dir_);
  ASSERT_EQ(views.size(), 2u);
  EXPECT_EQ(views[1].name, "p1.png");
  // Keeping the words would take well over 100 MB; a line at a time takes nothing of the kind.
  EXPECT_LT(peakResidentKb() - before_kb, 8 * 1024);
}

TEST_F(ColmapModel, AQuaternionNotOfUnitLengthIsRefusedWithItsNorm) {
  writeFile("cameras.txt", kCamerasText);
  const std::string images = dir_ + "/images.txt";
  writeFile("images.txt", "1 2 0 0 0 0 0 2 1 a.png\n");
  EXPECT_EQ(errorOf(), images +
                           ":1: the quaternion (2, 0, 0, 0) is not of unit length: its norm is 2 "
                           "(1 to within 0.01 is normalised)");
  writeFile("images.txt", "1 1e-07 0 0 0 0 0 2 1 a.png\n");
  EXPECT_EQ(errorOf(), images +
                           ":1: the quaternion (1e-07, 0, 0, 0) is not of unit length: its norm "
                           "is 1e-07 (1 to within 0.01 is normalised)");
  // Rounded to four digits, as some exporters write them: normalised.
  writeFile("images.txt", "1 0.7071 0.7071 0 0 0 0 2 1 a.png\n");
  const std::vector<CalibratedView> views = readColmapModel(dir_);
  const Eigen::Matrix3d expected =
      Eigen::AngleAxisd(M_PI / 2, Eigen::Vector3d::UnitX()).toRotationMatrix();
  EXPECT_TRUE(views[0].camera.R().isApprox(expected, 1e-12)) << views[0].camera.R();
}

TEST_F(ColmapModel, AByteOrderMarkIsSkipped) {
  writeText();
  const std::vector<CalibratedView> plain = readColmapModel(dir_);
  writeFile("cameras.txt", "\xEF\xBB\xBF" + kCamerasText);
  std::ifstream images_in(dir_ + "/images.txt");
  const std::string images((std::istreambuf_iterator<char>(images_in)),
                           std::istreambuf_iterator<char>());
  writeFile("images.txt", "\xEF\xBB\xBF" + images);
  const std::vector<CalibratedView> marked = readColmapModel(dir_);
  ASSERT_EQ(marked.size(), plain.size());
  for (size_t i = 0; i < plain.size(); ++i) {
    EXPECT_EQ(marked[i].name, plain[i].name);
    EXPECT_TRUE(marked[i].camera.projectionMatrix().isApprox(plain[i].camera.projectionMatrix()));
  }
}

TEST_F(ColmapModel, TheCameraSizeIsCheckedAgainstTheImage) {
  writeText();
  const std::vector<CalibratedView> views = readColmapModel(dir_);  // b.png: camera 1, 640x480
  ASSERT_EQ(views[1].name, "b.png");
  EXPECT_EQ(views[1].size_source, dir_ + "/cameras.txt:2");
  ASSERT_TRUE(cv::imwrite(dir_ + "/b.png", cv::Mat(480, 640, CV_8UC3, cv::Scalar::all(9))));
  EXPECT_EQ(loadViewImage(dir_, views[1]).size(), cv::Size(640, 480));
  ASSERT_TRUE(cv::imwrite(dir_ + "/b.png", cv::Mat(240, 320, CV_8UC3, cv::Scalar::all(9))));
  try {
    loadViewImage(dir_, views[1]);
    FAIL() << "no error";
  } catch (const std::runtime_error& e) {
    EXPECT_EQ(std::string(e.what()), dir_ +
                                         "/cameras.txt:2: the camera of view 'b.png' is 640x480 "
                                         "(WIDTH x HEIGHT) but the image " +
                                         dir_ + "/b.png is 320x240");
  }
  // The binary model names the camera by id and byte.
  writeFile("cameras.bin", camerasBin());
  writeFile("images.bin", imagesBin());
  ::unlink((dir_ + "/cameras.txt").c_str());
  EXPECT_EQ(readColmapModel(dir_)[1].size_source, dir_ + "/cameras.bin (camera 1 at byte 8)");
}

}  // namespace
}  // namespace sift_hull
