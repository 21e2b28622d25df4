#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <cmath>
#include <cstdlib>
#include <cstring>
#include <fstream>
#include <opencv2/core.hpp>
#include <opencv2/imgcodecs.hpp>
#include <sstream>

#include "common/test_data.h"
#include "sift_hull/io/calibration.h"
#include "sift_hull/io/llff.h"

namespace sift_hull {
namespace {

/// A .npy file: version 1.0 (or `major`.0), header dict, then the doubles as given.
std::string npyBytes(const std::string& dict, const std::vector<double>& data, int major = 1) {
  std::string header = dict;
  const size_t fixed = major == 1 ? 10 : 12;
  while ((fixed + header.size() + 1) % 64 != 0) header.push_back(' ');
  header.push_back('\n');
  std::string out = "\x93NUMPY";
  out.push_back(static_cast<char>(major));
  out.push_back('\0');
  const uint32_t length = static_cast<uint32_t>(header.size());
  out.append(reinterpret_cast<const char*>(&length), major == 1 ? 2 : 4);
  out += header;
  out.append(reinterpret_cast<const char*>(data.data()), data.size() * sizeof(double));
  return out;
}

std::string dictFor(size_t rows, bool fortran = false, const std::string& descr = "<f8",
                    const std::string& cols = "17") {
  return "{'descr': '" + descr + "', 'fortran_order': " + (fortran ? "True" : "False") +
         ", 'shape': (" + std::to_string(rows) + ", " + cols + "), }";
}

struct KnownView {
  Eigen::Matrix3d R_c2w_cv;  // camera-to-world, OpenCV axes
  Eigen::Vector3d centre;
};

const double kHeight = 378, kWidth = 504, kFocal = 407.5;

std::vector<KnownView> knownViews() {
  return {{Eigen::AngleAxisd(0.2, Eigen::Vector3d(0, 1, 0)).toRotationMatrix(), {0.5, 0.1, -3}},
          {Eigen::AngleAxisd(-0.4, Eigen::Vector3d(1, 0, 1).normalized()).toRotationMatrix(),
           {-0.2, 0.3, -2.5}}};
}

/// poses_bounds rows (row-major N x 17) for the known views, in LLFF's axes.
std::vector<double> llffRows(const std::vector<KnownView>& views) {
  std::vector<double> rows;
  for (const KnownView& v : views) {
    Eigen::Matrix<double, 3, 5> M;
    M.col(0) = v.R_c2w_cv.col(1);   // down
    M.col(1) = v.R_c2w_cv.col(0);   // right
    M.col(2) = -v.R_c2w_cv.col(2);  // backwards
    M.col(3) = v.centre;
    M.col(4) << kHeight, kWidth, kFocal;
    for (int r = 0; r < 3; ++r) {
      for (int c = 0; c < 5; ++c) rows.push_back(M(r, c));
    }
    rows.push_back(1.5);
    rows.push_back(8.0);
  }
  return rows;
}

std::vector<double> toFortran(const std::vector<double>& rows, size_t cols) {
  const size_t n = rows.size() / cols;
  std::vector<double> out(rows.size());
  for (size_t r = 0; r < n; ++r) {
    for (size_t c = 0; c < cols; ++c) out[c * n + r] = rows[r * cols + c];
  }
  return out;
}

class CalibrationFormats : public ::testing::Test {
 protected:
  void SetUp() override { dir_ = test::temporaryDirectory(); }
  std::string write(const std::string& name, const std::string& bytes) {
    std::ofstream(dir_ + "/" + name, std::ios::binary) << bytes;
    return dir_ + "/" + name;
  }
  std::string npyError(const std::string& bytes, size_t images = 2) {
    const std::string path = write("poses_bounds.npy", bytes);
    std::vector<std::string> names;
    for (size_t i = 0; i < images; ++i) names.push_back("img" + std::to_string(i) + ".png");
    try {
      readLlffPoses(path, names);
    } catch (const ParseError& e) {
      return e.what();
    }
    return "no error";
  }
  std::string dir_;
};

void expectKnownViews(const std::vector<CalibratedView>& views,
                      const std::vector<std::string>& names) {
  const auto known = knownViews();
  ASSERT_EQ(views.size(), known.size());
  Eigen::Matrix3d K;
  K << kFocal, 0, kWidth / 2 - 0.5, 0, kFocal, kHeight / 2 - 0.5, 0, 0, 1;
  for (size_t i = 0; i < known.size(); ++i) {
    EXPECT_EQ(views[i].name, names[i]);
    EXPECT_EQ(views[i].camera_model, "LLFF");
    EXPECT_TRUE(views[i].camera.K().isApprox(K, 1e-12));
    EXPECT_TRUE(views[i].camera.R().isApprox(known[i].R_c2w_cv.transpose(), 1e-12));
    EXPECT_TRUE(views[i].camera.centre().isApprox(known[i].centre, 1e-12));
    EXPECT_TRUE(views[i].camera.distortion().isZero());
  }
}

TEST_F(CalibrationFormats, LlffPosesGiveTheKnownCameras) {
  const std::vector<std::string> names = {"a.png", "b.JPG"};
  const auto rows = llffRows(knownViews());
  expectKnownViews(readLlffPoses(write("p.npy", npyBytes(dictFor(2), rows)), names), names);
  expectKnownViews(
      readLlffPoses(write("p.npy", npyBytes(dictFor(2, true), toFortran(rows, 17))), names), names);
  expectKnownViews(readLlffPoses(write("p.npy", npyBytes(dictFor(2), rows, 2)), names), names);
  expectKnownViews(readLlffPoses(write("p.npy", npyBytes(dictFor(2), rows, 3)), names), names);
}

TEST_F(CalibrationFormats, LlffViewsAreTheSortedImagesOfTheDirectory) {
  const std::string images = dir_ + "/images";
  ASSERT_EQ(::system(("mkdir -p " + images).c_str()), 0);
  for (const char* name : {"b.JPG", "notes.txt", "a.png"}) std::ofstream(images + "/" + name);
  EXPECT_EQ(listImageFiles(images), (std::vector<std::string>{"a.png", "b.JPG"}));
  const std::string npy = write("poses_bounds.npy", npyBytes(dictFor(2), llffRows(knownViews())));
  expectKnownViews(readCalibrationWithImages(npy, images), {"a.png", "b.JPG"});
  EXPECT_EQ(calibrationFormat(npy), "LLFF poses_bounds.npy");
}

TEST_F(CalibrationFormats, LlffDownscaledImagesScaleTheIntrinsics) {
  const std::string images = dir_ + "/images_4";
  ASSERT_EQ(::system(("mkdir -p " + images).c_str()), 0);
  // 504x378 / 4 = 126x94.5: the copy is 126x95.
  for (const char* name : {"a.png", "b.png"}) {
    ASSERT_TRUE(cv::imwrite(images + "/" + name, cv::Mat(95, 126, CV_8UC3, cv::Scalar::all(0))));
  }
  const std::string npy = write("poses_bounds.npy", npyBytes(dictFor(2), llffRows(knownViews())));
  const std::vector<CalibratedView> views = readCalibrationWithImages(npy, images);
  ASSERT_EQ(views.size(), 2u);
  Eigen::Matrix3d K;
  K << kFocal / 4, 0, 62.5, 0, kFocal / 4, 47, 0, 0, 1;
  EXPECT_TRUE(views[0].camera.K().isApprox(K, 1e-12)) << views[0].camera.K();
  EXPECT_TRUE(views[1].camera.centre().isApprox(knownViews()[1].centre, 1e-12));
  // Another aspect ratio is not a downscaled copy.
  try {
    readLlffPoses(npy, {"a.png", "b.png"}, 200, 100);
    FAIL() << "no error";
  } catch (const ParseError& e) {
    EXPECT_EQ(std::string(e.what()), npy +
                                         ": row 0 (a.png): the images are 200x100 (width x "
                                         "height) but the poses' [height, width] is 378x504, "
                                         "not a downscaled copy of one factor");
  }
}

TEST_F(CalibrationFormats, LlffSwappedHeightAndWidthAreNamed) {
  const std::string npy = write("poses_bounds.npy", npyBytes(dictFor(2), llffRows(knownViews())));
  // The poses say 378 high and 504 wide; portrait images 378 wide and 504 high (or their
  // quarter-size copies) have the two sides the other way round.
  for (const auto& [width, height] : {std::pair<int, int>(378, 504), {95, 126}}) {
    try {
      readLlffPoses(npy, {"a.png", "b.png"}, width, height);
      FAIL() << "no error";
    } catch (const ParseError& e) {
      const std::string size = std::to_string(width) + "x" + std::to_string(height);
      EXPECT_EQ(std::string(e.what()),
                npy + ": row 0 (a.png): the images are " + size +
                    " (width x height) but the poses' [height, width] is 378x504: height and "
                    "width are swapped (the poses give height 378 and width 504; the images are " +
                    std::to_string(height) + " high and " + std::to_string(width) + " wide)");
    }
  }
}

TEST_F(CalibrationFormats, MalformedNpyIsRefusedNamingTheFile) {
  const std::string path = dir_ + "/poses_bounds.npy";
  const auto rows = llffRows(knownViews());
  EXPECT_EQ(npyError(npyBytes(dictFor(2), rows), 3),
            path + ": holds 2 poses but there are 3 images");
  std::string bad_magic = npyBytes(dictFor(2), rows);
  bad_magic[1] = 'X';
  EXPECT_EQ(npyError(bad_magic), path + ": not a .npy file (no \\x93NUMPY magic string)");
  EXPECT_EQ(npyError(npyBytes(dictFor(2), rows, 4)),
            path + ": .npy format version 4.0 is not supported (1.0, 2.0, 3.0 are)");
  EXPECT_EQ(npyError(npyBytes(dictFor(2, false, "<f4"), rows)),
            path + ": dtype '<f4' is not supported: expected little-endian float64 ('<f8')");
  EXPECT_EQ(npyError(npyBytes(dictFor(2, false, ">f8"), rows)),
            path + ": dtype '>f8' is not supported: expected little-endian float64 ('<f8')");
  EXPECT_EQ(npyError(npyBytes(dictFor(2, false, "<f8", "15"), rows)),
            path + ": array shape (2, 15) is not (N, 17) with N >= 1");
  EXPECT_EQ(npyError(npyBytes("{'descr': '<f8', 'fortran_order': 0, 'shape': (2, 17), }", rows)),
            path + ": fortran_order must be True or False, not '0'");
  EXPECT_EQ(npyError(npyBytes("{'descr': '<f8', 'shape': (2, 17), }", rows)),
            path + ": the .npy header has no 'fortran_order'");
  EXPECT_EQ(npyError(npyBytes("{'descr': '<f8', 'fortran_order': False, 'shape': (34,), }", rows)),
            path + ": array shape (34,) is not (N, 17) with N >= 1");
  const std::string good = npyBytes(dictFor(2), rows);
  EXPECT_EQ(npyError(good.substr(0, good.size() - 8)),
            path + ": shape (2, 17) needs 272 bytes of data, the file has 264");
  EXPECT_EQ(npyError(good.substr(0, 30)), path +
                                              ": the .npy header length 118 runs past the end of "
                                              "the file or the limit of 65536 bytes");
  EXPECT_EQ(npyError(npyBytes(dictFor(1000000000), rows)),
            path + ": 1000000000 rows, more than the limit of 1000000");
  auto nan_rows = rows;
  nan_rows[3] = std::nan("");
  EXPECT_EQ(npyError(npyBytes(dictFor(2), nan_rows)),
            path + ": row 0 (img0.png): a value is not finite");
  auto bad_focal = rows;
  bad_focal[14] = 0.0;
  EXPECT_EQ(npyError(npyBytes(dictFor(2), bad_focal)),
            path +
                ": row 0 (img0.png): [height, width, focal] must be positive (sides at most "
                "65536)");
  EXPECT_EQ(npyError(""), path + ": too short for a .npy file");
  EXPECT_EQ(npyError("x", 0), path + ": too short for a .npy file");
}

// ---- projection lists ---------------------------------------------------------------------------

const char* kOneLine = "a.png 500 0 320 10  0 500 240 20  0 0 1 2\n";

void expectSameViews(const std::vector<CalibratedView>& a, const std::vector<CalibratedView>& b) {
  ASSERT_EQ(a.size(), b.size());
  for (size_t i = 0; i < a.size(); ++i) {
    EXPECT_EQ(a[i].name, b[i].name);
    EXPECT_TRUE(a[i].camera.projectionMatrix().isApprox(b[i].camera.projectionMatrix(), 1e-12));
  }
}

TEST_F(CalibrationFormats, ThreeRowAndCommaProjectionsEqualTheOneLineForm) {
  // Two views, a.png and b.png, of the same camera: each image is listed once.
  const auto one_line = readProjectionList(
      write("one.txt", std::string(kOneLine) + "b" + std::string(kOneLine).substr(1)));
  ASSERT_EQ(one_line.size(), 2u);
  EXPECT_EQ(one_line[0].camera_model, "projection");
  expectSameViews(one_line, readProjectionList(
                                write("rows.txt",
                                      "# name on its own line\na.png\n500 0 320 10\n0 500 240 20\n"
                                      "0 0 1 2\n\nb.png 500 0 320 10\n0 500 240 20\n0 0 1 2\n")));
  expectSameViews(one_line,
                  readCalibration(write("commas.txt",
                                        "a.png, 500, 0, 320, 10, 0, 500, 240, 20, 0, 0, 1, 2\n"
                                        "b.png\n500,0,320,10,0,500,240,20,0,0,1,2\n")));
  const auto unnamed =
      readProjectionList(write("unnamed.txt", "500 0 320 10\n0 500 240 20\n0 0 1 2\n"));
  ASSERT_EQ(unnamed.size(), 1u);
  EXPECT_EQ(unnamed[0].name, "");
  EXPECT_TRUE(unnamed[0].camera.projectionMatrix().isApprox(one_line[0].camera.projectionMatrix()));
}

TEST_F(CalibrationFormats, ThreeRowErrorsNameTheRightLine) {
  const std::string path = write("bad.txt", "a.png\n500 0 320 10\n0 500 240\n0 0 1 2\n");
  try {
    readProjectionList(path);
    FAIL() << "no error";
  } catch (const ParseError& e) {
    EXPECT_EQ(std::string(e.what()),
              path + ":3: expected row 2 of a 3x4 matrix (4 numbers), found 3 fields");
  }
  const std::string truncated = write("short.txt", "# c\na.png 500 0 320 10\n0 500 240 20\n");
  try {
    readProjectionList(truncated);
    FAIL() << "no error";
  } catch (const ParseError& e) {
    EXPECT_EQ(std::string(e.what()),
              truncated + ":3: the file ends inside a matrix: expected 3 rows of 4 numbers");
  }
  const std::string nan = write("nan.txt", "500 0 320 10\n0 500 240 20\n0 0 nan 2\n");
  try {
    readProjectionList(nan);
    FAIL() << "no error";
  } catch (const ParseError& e) {
    EXPECT_EQ(std::string(e.what()), nan + ":3: 'nan' is not finite");
  }
}

TEST_F(CalibrationFormats, ParAndProjectionViewsNameTheirModel) {
  const auto par = readCalibration(
      write("par.txt", "1\nv.png 500 0 320 0 500 240 0 0 1  1 0 0 0 1 0 0 0 1  0 0 2\n"));
  EXPECT_EQ(par[0].camera_model, "par");
  EXPECT_EQ(calibrationFormat(dir_ + "/par.txt"), "Middlebury par");
  EXPECT_EQ(describeDistortion(LensDistortion()), "no distortion");
  LensDistortion d;
  d.k1 = -0.25;
  d.p2 = 0.5;
  EXPECT_EQ(describeDistortion(d), "k1=-0.25 p2=0.5");
}

TEST_F(CalibrationFormats, DatasetInfoNamesTheFormatAndWhyThereIsNoCommonPoint) {
  for (const char* name : {"a.png", "b.png"}) {
    cv::imwrite(dir_ + "/" + name, cv::Mat(48, 64, CV_8UC3, cv::Scalar::all(200)));
  }
  write("cameras.txt", "1 OPENCV 64 48 50 50 32 24 -0.1 0 0 0\n");
  write("images.txt", "1 1 0 0 0 0 0 2 1 a.png\n\n2 1 0 0 0 0.5 0 2 1 b.png\n\n");
  std::string out, err;
  ASSERT_EQ(test::runProgram("dataset-info --calib " + dir_, &out, &err), 0) << err;
  EXPECT_NE(out.find("format: COLMAP text (cameras.txt, images.txt), camera model OPENCV, k1=-0.1"),
            std::string::npos)
      << out;
  EXPECT_NE(out.find("cameras look at a common point: no: the optical axes are (nearly) parallel"),
            std::string::npos)
      << out;
  // b.png looks away from where the axes meet.
  const std::string par = write("par.txt",
                                "2\na.png 50 0 32 0 50 24 0 0 1  1 0 0 0 1 0 0 0 1  0 0 2\n"
                                "b.png 50 0 32 0 50 24 0 0 1  0 0 1 0 1 0 -1 0 0  0 0 -2\n");
  ASSERT_EQ(test::runProgram("dataset-info --calib " + par, &out, &err), 0) << err;
  EXPECT_NE(out.find("format: Middlebury par, camera model par, no distortion"), std::string::npos)
      << out;
  EXPECT_NE(out.find(": the point is behind camera b.png"), std::string::npos) << out;
  ASSERT_EQ(test::runProgram("dataset-info --json --calib " + par, &out, &err), 0) << err;
  EXPECT_NE(out.find("\"reason\": \"the point is behind camera b.png\""), std::string::npos) << out;
}

}  // namespace
}  // namespace sift_hull
