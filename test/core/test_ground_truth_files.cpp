// The ground-truth file readers (io/ground_truth_files.h): Oxford homographies and disparity maps.

#include <gtest/gtest.h>

#include <cmath>
#include <fstream>
#include <opencv2/imgcodecs.hpp>
#include <stdexcept>
#include <string>

#include "common/test_data.h"
#include "sift_hull/io/calibration.h"
#include "sift_hull/io/ground_truth_files.h"

namespace sift_hull {
namespace {

std::string writeFile(const std::string& name, const std::string& text) {
  const std::string path = test::temporaryDirectory() + "/" + name;
  std::ofstream(path) << text;
  return path;
}

/// The message of the std::runtime_error `read` throws, or "" when it throws none.
template <typename Read>
std::string runtimeErrorOf(Read read) {
  try {
    read();
  } catch (const std::runtime_error& e) {
    return e.what();
  }
  return "";
}

// ---- readHomography -----------------------------------------------------------------------------

TEST(ReadHomography, ReadsOxfordGraf) {
  SIFT_HULL_REQUIRE_DATA(dir, "oxford_affine_graf");
  const Eigen::Matrix3d H = readHomography(dir + "/H1to2p");
  Eigen::Matrix3d expected;  // from the data set's README
  expected << 8.7976964e-01, 3.1245438e-01, -3.9430589e+01, -1.8389418e-01, 9.3847198e-01,
      1.5315784e+02, 1.9641425e-04, -1.6015275e-05, 1.0000000e+00;
  EXPECT_EQ(H, expected);
}

TEST(ReadHomography, ReadsRowMajorWhateverTheWhitespace) {
  const std::string path = writeFile("H", "1 2\t3\n\n  4 5 6 7\n8 9e-1\n");
  Eigen::Matrix3d expected;
  expected << 1, 2, 3, 4, 5, 6, 7, 8, 0.9;
  EXPECT_EQ(readHomography(path), expected);
}

TEST(ReadHomography, MalformedFilesThrowParseErrorNamingTheFile) {
  static_assert(std::is_base_of_v<std::runtime_error, ParseError>);
  for (const char* text :
       {"1 2 3\n4 5 6\n7 8\n", "1 2 3\n4 5 6\n7 8 9 10\n", "1 2 3\n4 five 6\n7 8 9\n",
        "1 2 3\n4 nan 6\n7 8 9\n", "1 2 3\n4 5 6\n7 8 1e999\n", ""}) {
    const std::string path = writeFile("H", text);
    EXPECT_THROW(readHomography(path), ParseError) << text;
    const std::string message = runtimeErrorOf([&] { readHomography(path); });
    EXPECT_NE(message.find(path), std::string::npos) << message;
  }
}

TEST(ReadHomography, MissingFileThrowsNamingIt) {
  const std::string path = test::temporaryDirectory() + "/absent";
  const std::string message = runtimeErrorOf([&] { readHomography(path); });
  EXPECT_NE(message.find(path), std::string::npos) << message;
}

// ---- readDisparity ------------------------------------------------------------------------------

TEST(ReadDisparity, ReadsTeddyInPixels) {
  SIFT_HULL_REQUIRE_DATA(dir, "middlebury_stereo2003_teddy");
  const cv::Mat disparity = readDisparity(dir + "/disp2.pgm", 4.0);
  ASSERT_EQ(disparity.type(), CV_32FC1);
  EXPECT_EQ(disparity.size(), cv::Size(450, 375));
  double lo, hi;
  cv::minMaxLoc(disparity, &lo, &hi);
  EXPECT_EQ(lo, 0.0);
  EXPECT_EQ(hi, 211.0 / 4.0);  // values from the data set's README
  EXPECT_EQ(disparity.total() - cv::countNonZero(disparity), 3406u);
}

TEST(ReadDisparity, MissingFileThrowsNamingIt) {
  const std::string path = test::temporaryDirectory() + "/absent.pgm";
  const std::string message = runtimeErrorOf([&] { readDisparity(path, 4.0); });
  EXPECT_NE(message.find(path), std::string::npos) << message;
}

}  // namespace
}  // namespace sift_hull
