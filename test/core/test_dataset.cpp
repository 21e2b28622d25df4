#include <gtest/gtest.h>

#include <cstdio>
#include <fstream>
#include <nlohmann/json.hpp>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include "common/test_data.h"
#include "sift_hull/geometry/camera_set.h"
#include "sift_hull/hull/silhouette.h"
#include "sift_hull/io/calibration.h"
#include "sift_hull/io/images.h"

namespace sift_hull {
namespace {

const char* kDino = "middlebury_mvs_dinoSparseRing";
const char* kTemple = "middlebury_mvs_templeSparseRing";

// A valid par line: K, identity R, t putting the origin 2 m in front of the camera.
const char* kGoodLine = "view.png 500 0 320 0 500 240 0 0 1  1 0 0 0 1 0 0 0 1  0 0 2";

class MalformedFile : public ::testing::Test {
 protected:
  void SetUp() override { dir_ = test::temporaryDirectory(); }
  std::string write(const std::string& text) {
    const std::string path = dir_ + "/calib.txt";
    std::ofstream(path) << text;
    return path;
  }
  /// The ParseError message of reading `text` with `reader`, or "no error".
  template <typename Reader>
  std::string errorOf(const std::string& text, Reader reader) {
    const std::string path = write(text);
    try {
      reader(path);
    } catch (const ParseError& e) {
      return e.what();
    }
    return "no error";
  }
  std::string dir_;
};

TEST_F(MalformedFile, WellFormedParFileLoads) {
  const std::string second = std::string(kGoodLine).replace(0, 4, "next");
  const auto views =
      readMiddleburyPar(write(std::string("2\n") + kGoodLine + "\n" + second + "\n"));
  ASSERT_EQ(views.size(), 2u);
  EXPECT_EQ(views[1].name, "next.png");
  EXPECT_EQ(views[0].name, "view.png");
  EXPECT_NEAR(views[1].camera.project(Eigen::Vector3d(0, 0, 0)).x(), 320.0, 1e-12);
}

TEST_F(MalformedFile, ParErrorsNameFileAndLine) {
  const std::string path = dir_ + "/calib.txt";
  const std::string good = kGoodLine;
  EXPECT_EQ(errorOf("2\n" + good + "\nview2.png 1 2 3\n", readMiddleburyPar),
            path + ":3: expected 22 fields (name, K, R, t), found 4");
  EXPECT_EQ(
      errorOf("1\nv.png 500 0 320 0 abc 240 0 0 1 1 0 0 0 1 0 0 0 1 0 0 2\n", readMiddleburyPar),
      path + ":2: 'abc' is not a number");
  EXPECT_EQ(
      errorOf("1\nv.png 500 0 320 0 500 240 0 0 1 1 0 0 0 1 0 0 0 1 0 nan 2\n", readMiddleburyPar),
      path + ":2: 'nan' is not finite");
  EXPECT_EQ(
      errorOf("1\nv.png 500 0 320 0 0 240 0 0 1 1 0 0 0 1 0 0 0 1 0 0 2\n", readMiddleburyPar),
      path + ":2: K is singular");
  EXPECT_EQ(
      errorOf("1\nv.png 500 0 320 0 500 240 0 0 1 1 0 0 0 1 0 0 0 2 0 0 2\n", readMiddleburyPar),
      path + ":2: R is not orthonormal (max |R^T R - I| = 3.000000)");
  EXPECT_EQ(errorOf("3\n" + good + "\n" + good + "\n", readMiddleburyPar),
            path + ":1: count line says 3 views but the file has 2");
  EXPECT_EQ(errorOf("two\n" + good + "\n", readMiddleburyPar),
            path + ":1: expected a count line with the number of views");
  EXPECT_EQ(errorOf("", readMiddleburyPar), path + ": empty file, expected a count line");
  EXPECT_EQ(errorOf("1\n" + good + "\n" + good + "\n", readMiddleburyPar),
            path + ":1: count line says 1 views but the file has 2");
  EXPECT_EQ(errorOf("0\n", readMiddleburyPar),
            path + ":1: the count line must give between 1 and 1000000 views, not 0");
  EXPECT_EQ(errorOf("99999999999\n" + good + "\n", readMiddleburyPar),
            path + ":1: the count line must give between 1 and 1000000 views, not 99999999999");
  EXPECT_EQ(errorOf(good + "\n", readCalibration),
            path + ":1: a Middlebury par line, but the file has no count line before it");
  EXPECT_EQ(errorOf("x", [](const std::string&) { readMiddleburyPar("/nonexistent/par.txt"); }),
            "/nonexistent/par.txt: cannot open file");
}

TEST_F(MalformedFile, BadIntrinsicsAndRotationsAreNamed) {
  const std::string path = dir_ + "/calib.txt";
  const auto par = [](const std::string& K, const std::string& R) {
    return "1\nv.png " + K + " " + R + " 0 0 2\n";
  };
  const std::string K = "500 0 320 0 500 240 0 0 1", R = "1 0 0 0 1 0 0 0 1";
  EXPECT_EQ(errorOf(par(K, "1 0 0 0 1 0 0 0 -1"), readMiddleburyPar),
            path + ":2: R has det -1 (a reflection)");
  EXPECT_EQ(errorOf(par("500 0 320 3 500 240 0 0 1", R), readMiddleburyPar),
            path + ":2: K is not upper triangular");
  EXPECT_EQ(errorOf(par("-500 0 320 0 500 240 0 0 1", R), readMiddleburyPar),
            path + ":2: K has a non-positive focal length");
  EXPECT_EQ(errorOf(par("500 0 320 0 500 240 0 0 0", R), readMiddleburyPar),
            path + ":2: K(3,3) is zero");
  // Numbers too small for a double read as zero rather than as an error.
  EXPECT_EQ(errorOf(par("500 1e-320 320 0 500 240 0 0 1", R), readMiddleburyPar), "no error");
}

TEST_F(MalformedFile, ProjectionListErrorsNameFileAndLine) {
  const std::string path = dir_ + "/calib.txt";
  EXPECT_EQ(errorOf("# comment\n500 0 320 0  0 500 240 0  0 0 1\n", readProjectionList),
            path +
                ":2: expected 12 numbers of a 3x4 matrix (or a row of 4), optionally after a name; "
                "found 11 fields");
  EXPECT_EQ(errorOf("7 500 0 320 0  0 500 240 0  0 0 1 2\n", readProjectionList),
            path + ":1: expected an image name before the 12 numbers, found '7'");
  EXPECT_EQ(errorOf("a.png 1 0 0 0  1 0 0 0  0 0 0 1\n", readProjectionList),
            path + ":1: the left 3x3 block of P is singular");
  EXPECT_EQ(errorOf("a.png 1 0 0 0  0 1 0 0  0 0 1 inf\n", readProjectionList),
            path + ":1: 'inf' is not finite");
}

TEST_F(MalformedFile, AViewListedTwiceIsRefusedNamingBothLines) {
  const std::string path = dir_ + "/calib.txt";
  const std::string good = kGoodLine;
  const std::string other = std::string(kGoodLine).replace(0, 4, "next");
  EXPECT_EQ(errorOf("3\n" + good + "\n" + other + "\n" + good + "\n", readMiddleburyPar),
            path +
                ":4: image 'view.png' is given twice, on lines 2 and 4: each view must be "
                "listed once");
  const std::string P = "500 0 320 0  0 500 240 1000  0 0 1 2";
  EXPECT_EQ(
      errorOf("# list\na.png " + P + "\nb.png " + P + "\na.png\n" + P + "\n", readProjectionList),
      path +
          ":4: image 'a.png' is given twice, on lines 2 and 4: each view must be listed "
          "once");
}

TEST_F(MalformedFile, AByteOrderMarkBeforeTheCountLineIsSkipped) {
  const std::string text = std::string("1\n") + kGoodLine + "\n";
  const PinholeCamera plain = readCalibration(write(text))[0].camera;
  EXPECT_EQ(calibrationFormat(write("\xEF\xBB\xBF" + text)), "Middlebury par");
  const std::vector<CalibratedView> marked = readCalibration(write("\xEF\xBB\xBF" + text));
  ASSERT_EQ(marked.size(), 1u);
  EXPECT_EQ(marked[0].name, "view.png");
  EXPECT_TRUE(marked[0].camera.projectionMatrix().isApprox(plain.projectionMatrix(), 1e-15));
}

TEST_F(MalformedFile, ProjectionListMatchesParFile) {
  const PinholeCamera camera = readMiddleburyPar(write(std::string("1\n") + kGoodLine))[0].camera;
  std::ostringstream line;
  line.precision(17);
  line << "view.png";
  const Matrix34d P = 3.0 * camera.projectionMatrix();
  for (int r = 0; r < 3; ++r) {
    for (int c = 0; c < 4; ++c) line << ' ' << P(r, c);
  }
  const auto views = readCalibration(write(line.str() + "\n"));
  ASSERT_EQ(views.size(), 1u);
  EXPECT_EQ(views[0].name, "view.png");
  EXPECT_LT((views[0].camera.K() - camera.K()).norm(), 1e-9);
  EXPECT_LT((views[0].camera.t() - camera.t()).norm(), 1e-9);
}

TEST_F(MalformedFile, MissingImageIsNamedWithTheLineNamingIt) {
  const std::string path = write(std::string("1\n") + kGoodLine);
  std::string out, err;
  EXPECT_EQ(test::runProgram("dataset-info --calib " + path, &out, &err), 1);
  EXPECT_NE(err.find(dir_ + "/view.png: image missing or unreadable (named at " + path + ":2)"),
            std::string::npos)
      << err;
  const auto unnamed = readProjectionList(write("500 0 320 0  0 500 240 0  0 0 1 2\n"));
  try {
    loadViewImage(dir_, unnamed[0]);
    FAIL() << "expected an error";
  } catch (const std::runtime_error& e) {
    EXPECT_EQ(std::string(e.what()),
              path + ":1: no image name for this view; put one before its numbers");
  }
}

TEST_F(MalformedFile, ImagesOfDifferentSizesAreNamed) {
  const std::string line2 = std::string(kGoodLine).replace(0, 8, "other.png");
  const std::string path = write("2\n" + std::string(kGoodLine) + "\n" + line2 + "\n");
  cv::imwrite(dir_ + "/view.png", cv::Mat(48, 64, CV_8UC3, cv::Scalar::all(90)));
  cv::imwrite(dir_ + "/other.png", cv::Mat(40, 64, CV_8UC3, cv::Scalar::all(90)));
  std::string out, err;
  EXPECT_EQ(test::runProgram("dataset-info --calib " + path, &out, &err), 1);
  EXPECT_NE(err.find(dir_ + "/other.png: image size differs from view.png's"), std::string::npos)
      << err;
}

TEST_F(MalformedFile, WriteThenReadParIsExact) {
  const auto views = readMiddleburyPar(write(std::string("1\n") + kGoodLine));
  const std::string path = dir_ + "/copy_par.txt";
  writeMiddleburyPar(path, views);
  const auto again = readMiddleburyPar(path);
  ASSERT_EQ(again.size(), 1u);
  EXPECT_EQ(again[0].camera.projectionMatrix(), views[0].camera.projectionMatrix());
}

TEST(Silhouette, MiddleburyRecipeFillsShadowsAndGrowsByThreeClosingPixels) {
  cv::Mat image(200, 200, CV_8UC3, cv::Scalar::all(0));
  cv::circle(image, {100, 100}, 50, cv::Scalar::all(200), cv::FILLED);
  cv::circle(image, {100, 100}, 3, cv::Scalar::all(20), cv::FILLED);  // a dark shadow inside
  SilhouetteConfig recipe;
  recipe.silhouette_method = "threshold";
  const cv::Mat mask = silhouetteFromImage(image, recipe);
  EXPECT_EQ(mask.at<uint8_t>(100, 100), 255);       // the shadow is closed
  EXPECT_EQ(mask.at<uint8_t>(100, 100 + 52), 255);  // dilate 10 then erode 7 grows ~3 px
  EXPECT_EQ(mask.at<uint8_t>(100, 100 + 55), 0);
  const double area = cv::countNonZero(mask);
  EXPECT_NEAR(area, CV_PI * 53 * 53, 0.03 * CV_PI * 53 * 53);
  SilhouetteConfig raw = recipe;
  raw.dilate_px = raw.erode_px = 0;
  EXPECT_EQ(silhouetteFromImage(image, raw).at<uint8_t>(100, 100), 0);
}

TEST(Silhouette, LoadMaskMakesBinary) {
  const std::string dir = test::temporaryDirectory();
  cv::Mat raw(10, 10, CV_8UC1, cv::Scalar(0));
  raw.at<uint8_t>(2, 3) = 1;
  cv::imwrite(dir + "/m.png", raw);
  const cv::Mat mask = loadMask(dir + "/m.png");
  EXPECT_EQ(mask.at<uint8_t>(2, 3), 255);
  EXPECT_EQ(cv::countNonZero(mask), 1);
  EXPECT_THROW(loadMask(dir + "/absent.png"), std::runtime_error);
}

/// Loads a Middlebury ring and checks the centre of its known bounding box projects into every
/// image.
void checkRing(const std::string& dir, const std::string& par, const Eigen::Vector3d& lo,
               const Eigen::Vector3d& hi) {
  const auto views = readMiddleburyPar(dir + "/" + par);
  ASSERT_EQ(views.size(), 16u);
  const Eigen::Vector3d centre = 0.5 * (lo + hi);
  for (const CalibratedView& view : views) {
    const cv::Mat image = loadViewImage(dir, view);
    ASSERT_EQ(image.size(), cv::Size(640, 480)) << view.name;
    EXPECT_GT(view.camera.depth(centre), 0.0) << view.name;
    const Eigen::Vector2d pixel = view.camera.project(centre);
    EXPECT_TRUE(pixel.x() > 0 && pixel.x() < 640 && pixel.y() > 0 && pixel.y() < 480)
        << view.name << " sees the box centre at " << pixel.transpose();
  }
  const CommonPoint common = opticalAxesMeetingPoint(camerasOf(views));
  EXPECT_TRUE(common.well_defined && common.in_front_of_all);
  // The ring's axes meet near the object: within twice the box's half diagonal of its centre.
  EXPECT_LT((common.point_W - centre).norm(), (hi - lo).norm());
}

TEST(MiddleburyData, DinoRingLoads) {
  SIFT_HULL_REQUIRE_DATA(dir, kDino);
  checkRing(dir, "dinoSR_par.txt", {-0.061897, -0.018874, -0.057845},
            {0.010897, 0.068227, 0.015495});
}

TEST(MiddleburyData, TempleRingLoads) {
  SIFT_HULL_REQUIRE_DATA(dir, kTemple);
  checkRing(dir, "templeSR_par.txt", {-0.073568, 0.021728, -0.012445},
            {0.028855, 0.181892, 0.062736});
}

TEST(DatasetInfoCommand, ReportsDinoAsJson) {
  SIFT_HULL_REQUIRE_DATA(dir, kDino);
  std::string out, err;
  ASSERT_EQ(test::runProgram("dataset-info --calib " + dir + "/dinoSR_par.txt --json", &out, &err),
            0)
      << err;
  const nlohmann::json info = nlohmann::json::parse(out);
  EXPECT_EQ(info["views"], 16);
  EXPECT_EQ(info["image_size"], nlohmann::json({640, 480}));
  EXPECT_EQ(info["common_point"]["looks_at_common_point"], true);
  const auto views = readMiddleburyPar(dir + "/dinoSR_par.txt");
  ASSERT_EQ(info["cameras"].size(), 16u);
  for (size_t i = 0; i < views.size(); ++i) {
    const auto& camera = info["cameras"][i];
    EXPECT_EQ(camera["name"], views[i].name);
    const Eigen::Vector3d centre(camera["centre"][0], camera["centre"][1], camera["centre"][2]);
    EXPECT_LT((centre - views[i].camera.centre()).norm(), 1e-12);
    // The dino fills a large part of every view (measured 25 % to 50 % with the recipe).
    EXPECT_GT(camera["silhouette_fraction"].get<double>(), 0.2);
    EXPECT_LT(camera["silhouette_fraction"].get<double>(), 0.6);
  }
}

TEST(DatasetInfoCommand, MalformedFileGivesLocatedErrorAndExitCode) {
  const std::string dir = test::temporaryDirectory();
  std::ofstream(dir + "/bad_par.txt") << "1\nview.png 1 2 3\n";
  std::string out, err;
  EXPECT_EQ(test::runProgram("dataset-info --calib " + dir + "/bad_par.txt", &out, &err), 1);
  EXPECT_NE(err.find(dir + "/bad_par.txt:2: expected 22 fields"), std::string::npos) << err;
  EXPECT_TRUE(out.empty());
  EXPECT_EQ(test::runProgram("dataset-info --no-such-option", &out, &err), 2);
  EXPECT_NE(err.find("unknown option --no-such-option"), std::string::npos) << err;
}

}  // namespace
}  // namespace sift_hull
