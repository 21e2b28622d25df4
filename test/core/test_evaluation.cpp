#include <gtest/gtest.h>

#include <cmath>
#include <fstream>
#include <map>
#include <nlohmann/json.hpp>
#include <opencv2/imgcodecs.hpp>
#include <string>
#include <type_traits>
#include <utility>
#include <vector>

#include "common/test_data.h"
#include "sift_hull/eval/match_evaluation.h"
#include "sift_hull/features/labelled_matches.h"
#include "sift_hull/filters/filter.h"
#include "sift_hull/filters/filter_result.h"
#include "sift_hull/filters/ratio.h"
#include "sift_hull/io/calibration.h"
#include "sift_hull/io/ground_truth_files.h"
#include "sift_hull/synthetic/scene.h"

namespace sift_hull {
namespace {

using Point = cv::Point2f;

/// Matches i -> i between the given left and right points, in images of `size`.
PutativeMatches pointPairs(const std::vector<std::pair<Point, Point>>& pairs,
                           cv::Size size = {40, 30}) {
  PutativeMatches input;
  input.left_image_size = input.right_image_size = size;
  for (size_t i = 0; i < pairs.size(); ++i) {
    input.left_keypoints.emplace_back(pairs[i].first, 4.f);
    input.right_keypoints.emplace_back(pairs[i].second, 4.f);
    input.matches.emplace_back(static_cast<int>(i), static_cast<int>(i), 0.f);
  }
  return input;
}

constexpr MatchTruth kCorrect = MatchTruth::kCorrect;
constexpr MatchTruth kWrong = MatchTruth::kWrong;
constexpr MatchTruth kUnknown = MatchTruth::kUnknown;

// ---- judging single matches ---------------------------------------------------------------------

TEST(JudgeByDisparity, ChecksRowAndColumnAtTheNearestPixelsDisparity) {
  cv::Mat disparity(30, 40, CV_32FC1, cv::Scalar(5.0f));
  disparity.at<float>(10, 21) = 0.0f;  // unknown
  const PutativeMatches input = pointPairs({
      {{20, 10}, {15, 10}},        // exact
      {{20, 10}, {16.9f, 10.9f}},  // within 1 px of the row and 2 px of the column
      {{20, 10}, {15, 11.5f}},     // off the row
      {{20, 10}, {17.5f, 10}},     // wrong disparity
      {{20.6f, 10}, {15.6f, 10}},  // nearest pixel (21, 10) has no disparity
      {{20.4f, 10}, {15.4f, 10}},  // nearest pixel (20, 10) has one
      {{-3, 10}, {-8, 10}},        // outside the left image
      {{20, 30.5f}, {15, 30.5f}},  // outside, below
      {{NAN, 10}, {15, 10}},       // not a number
      {{20, 10}, {15, NAN}},       //
      {{20, 10}, {INFINITY, 10}},  //
  });
  const std::vector<MatchTruth> expected = {kCorrect, kCorrect, kWrong, kWrong, kUnknown, kCorrect,
                                            kUnknown, kUnknown, kWrong, kWrong, kWrong};
  EXPECT_EQ(judgeByDisparity(input, disparity), expected);
  TruthTolerances loose;
  loose.max_column_error_px = 3.0;
  EXPECT_EQ(judgeByDisparity(input, disparity, loose)[3], kCorrect);
}

TEST(JudgeByHomography, ComparesWithTheMappedPoint) {
  Eigen::Matrix3d H;  // scale by 2, then shift by (5, -3)
  H << 2, 0, 5, 0, 2, -3, 0, 0, 1;
  const PutativeMatches input = pointPairs({
      {{10, 10}, {25, 17}},   // exact
      {{10, 10}, {27, 18}},   // 2.2 px off
      {{10, 10}, {25, 21}},   // 4 px off the row
      {{10, 10}, {21, 17}},   // 4 px off the column
      {{NAN, 10}, {25, 17}},  // not a number
      {{10, 10}, {25, NAN}},  //
  });
  EXPECT_EQ(judgeByHomography(input, H),
            std::vector<MatchTruth>({kCorrect, kCorrect, kWrong, kWrong, kWrong, kWrong}));
  EXPECT_EQ(judgeByHomography(input, 3.0 * H), judgeByHomography(input, H));
  EXPECT_EQ(judgeByHomography(input, -H), judgeByHomography(input, H));  // H is up to sign too
}

TEST(JudgeByHomography, DividesByTheHomogeneousCoordinate) {
  Eigen::Matrix3d H;  // (x, y) -> ((2x + 5) / w, (2y - 3) / w) with w = 1 + (x - y) / 10
  H << 2, 0, 5, 0, 2, -3, 0.1, -0.1, 1;
  const PutativeMatches input = pointPairs({
      {{10, 10}, {25, 17}},       // w = 1
      {{20, 10}, {22.5f, 8.5f}},  // w = 2
      {{20, 10}, {45, 17}},       // ignoring w
  });
  EXPECT_EQ(judgeByHomography(input, H), std::vector<MatchTruth>({kCorrect, kCorrect, kWrong}));
}

/// Two neighbouring views of the default scene, 30 degrees apart, with their depth maps.
class SceneDepthPair : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    for (int i = 0; i < 2; ++i) {
      const RenderedView view = renderSceneView(test::smallRing(), i);
      views_[i] = {view.view.camera, view.depth};
    }
  }
  /// The first pixel on a 7 px grid whose correspondence has the given visibility.
  static bool findPixel(Visibility wanted, Eigen::Vector2d* pixel) {
    for (int v = 0; v < views_[0].depth.rows; v += 7) {
      for (int u = 0; u < views_[0].depth.cols; u += 7) {
        *pixel = Eigen::Vector2d(u, v);
        if (trueCorrespondence(views_[0], views_[1], *pixel).visibility == wanted) return true;
      }
    }
    return false;
  }
  static DepthView views_[2];
};
DepthView SceneDepthPair::views_[2];

Point toPoint(const Eigen::Vector2d& pixel) { return Point(pixel.x(), pixel.y()); }

TEST_F(SceneDepthPair, JudgesByTheTrueCorrespondence) {
  Eigen::Vector2d seen, hidden;
  ASSERT_TRUE(findPixel(Visibility::kVisible, &seen));
  ASSERT_TRUE(findPixel(Visibility::kOccluded, &hidden));
  const Eigen::Vector2d target = trueCorrespondence(views_[0], views_[1], seen).pixel_b;
  const Eigen::Vector2d hidden_target = trueCorrespondence(views_[0], views_[1], hidden).pixel_b;
  const PutativeMatches input = pointPairs(
      {
          {toPoint(seen), toPoint(target)},
          {toPoint(seen), toPoint(target + Eigen::Vector2d(1.0, -1.0))},
          {toPoint(seen), toPoint(target + Eigen::Vector2d(5.0, 0.0))},
          {toPoint(hidden), toPoint(hidden_target)},
          {{0, 0}, toPoint(target)},  // a corner of the image sees the background
          {{NAN, 0}, toPoint(target)},
      },
      views_[0].depth.size());
  EXPECT_EQ(judgeBySceneDepth(input, views_[0], views_[1]),
            std::vector<MatchTruth>({kCorrect, kCorrect, kWrong, kWrong, kUnknown, kWrong}));
}

// ---- scoreFilter --------------------------------------------------------------------------------

FilterResult keeping(const std::vector<uint8_t>& keep) {
  FilterResult result;
  result.keep = keep;
  result.score.assign(keep.size(), 0.0);
  return result;
}

TEST(ScoreFilter, CountsEachTruthAndDerivesTheScores) {
  const std::vector<MatchTruth> truth = {kCorrect, kCorrect, kCorrect, kCorrect, kWrong,
                                         kWrong,   kWrong,   kUnknown, kUnknown};
  const FilterScores scores = scoreFilter(truth, keeping({1, 1, 0, 0, 1, 0, 0, 1, 1}));
  EXPECT_EQ(scores.putative, 9u);
  EXPECT_EQ(scores.kept, 5u);
  EXPECT_EQ(scores.correct_putative, 4u);
  EXPECT_EQ(scores.correct_kept, 2u);
  EXPECT_EQ(scores.wrong_putative, 3u);
  EXPECT_EQ(scores.wrong_kept, 1u);
  EXPECT_EQ(scores.unknown_putative, 2u);
  EXPECT_EQ(scores.unknown_kept, 2u);
  EXPECT_DOUBLE_EQ(scores.precision(), 2.0 / 3.0);  // unknown kept ones do not count
  EXPECT_DOUBLE_EQ(scores.recall(), 0.5);
  EXPECT_DOUBLE_EQ(scores.f1(), 4.0 / 7.0);
  EXPECT_EQ(scores.mismatchesRemoved(), 2u);
}

TEST(ScoreFilter, UndefinedScoresAreNan) {
  const std::vector<MatchTruth> truth = {kCorrect, kWrong, kUnknown};
  const FilterScores none_kept = scoreFilter(truth, keeping({0, 0, 0}));
  EXPECT_TRUE(std::isnan(none_kept.precision()));
  EXPECT_EQ(none_kept.recall(), 0.0);
  EXPECT_TRUE(std::isnan(none_kept.f1()));
  EXPECT_EQ(none_kept.mismatchesRemoved(), 1u);
  const FilterScores only_unknown_kept = scoreFilter(truth, keeping({0, 0, 1}));
  EXPECT_TRUE(std::isnan(only_unknown_kept.precision()));
  const FilterScores only_wrong_kept = scoreFilter(truth, keeping({0, 1, 0}));
  EXPECT_EQ(only_wrong_kept.precision(), 0.0);
  EXPECT_EQ(only_wrong_kept.f1(), 0.0);
  const FilterScores no_correct = scoreFilter({kWrong, kUnknown}, keeping({1, 1}));
  EXPECT_TRUE(std::isnan(no_correct.recall()));
}

TEST(ScoreFilter, SizeMismatchThrows) {
  EXPECT_THROW(scoreFilter({kCorrect, kWrong}, keeping({1})), std::invalid_argument);
  EXPECT_THROW(scoreFilter({}, keeping({1})), std::invalid_argument);
}

// ---- filters on real data -----------------------------------------------------------------------

/// Lower bounds on a filter's precision and recall, set a little under the measured values.
struct Floor {
  const char* filter;
  double precision;
  double recall;
};

/// Teddy's putative matches (ratio 0.8), judged by the left disparity; empty without the data.
const LabelledMatches& teddy() {
  static const LabelledMatches matches = [] {
    const std::string dir = test::dataSet("middlebury_stereo2003_teddy");
    MatchConfig matching;
    matching.ratio = 0.8;
    return dir.empty() ? LabelledMatches()
                       : matchRectifiedPair(dir + "/im2.png", dir + "/im6.png", dir + "/disp2.pgm",
                                            4.0, SiftConfig(), matching);
  }();
  return matches;
}

/// Graf 1-2's putative matches (ratio 0.8), judged by H1to2p; uncalibrated; empty without data.
const LabelledMatches& graf() {
  static const LabelledMatches matches = [] {
    const std::string dir = test::dataSet("oxford_affine_graf");
    MatchConfig matching;
    matching.ratio = 0.8;
    return dir.empty() ? LabelledMatches()
                       : matchPlanarPair(dir + "/img1.png", dir + "/img2.png", dir + "/H1to2p",
                                         SiftConfig(), matching);
  }();
  return matches;
}

FilterScores scoreByName(const LabelledMatches& pair, const std::string& filter) {
  const FilterResult result = makeFilter(filter, FilterConfigs())->apply(pair.putative);
  const FilterScores scores = scoreFilter(pair.truth, result);
  std::cout << filter << ": kept " << scores.kept << " of " << scores.putative << ", precision "
            << scores.precision() << ", recall " << scores.recall() << "\n";
  return scores;
}

void expectFloors(const LabelledMatches& pair, const std::vector<Floor>& floors) {
  for (const Floor& floor : floors) {
    const FilterScores scores = scoreByName(pair, floor.filter);
    EXPECT_GE(scores.precision(), floor.precision) << floor.filter;
    EXPECT_GE(scores.recall(), floor.recall) << floor.filter;
  }
}

TEST(RealData, TeddyPutativesHoldMismatchesToRemove) {
  SIFT_HULL_REQUIRE_DATA(dir, "middlebury_stereo2003_teddy");
  const FilterScores all = scoreFilter(teddy().truth, filterRatio(teddy().putative));
  EXPECT_EQ(all.kept, all.putative);
  EXPECT_GT(all.correct_putative, 250u);  // measured: 294 of 361
  EXPECT_GT(all.wrong_putative, 30u);     // measured: 54
  EXPECT_LT(all.unknown_putative, 30u);   // measured: 13
}

TEST(RealData, TeddyEpipolarKeepsEveryCorrectMatch) {
  SIFT_HULL_REQUIRE_DATA(dir, "middlebury_stereo2003_teddy");
  const FilterScores scores = scoreByName(teddy(), "epipolar");
  EXPECT_EQ(scores.recall(), 1.0);
  EXPECT_GT(scores.mismatchesRemoved(), 0u);
}

TEST(RealData, TeddyFiltersMeetTheirFloors) {
  SIFT_HULL_REQUIRE_DATA(dir, "middlebury_stereo2003_teddy");
  expectFloors(teddy(), {
                            {"ratio", 0.82, 0.98},      // measured: 0.845, 1.0
                            {"epipolar", 0.87, 0.98},   // measured: 0.891, 1.0
                            {"gsc", 0.85, 0.97},        // measured: 0.874, 0.993
                            {"ransac", 0.91, 0.94},     // measured: 0.934, 0.966
                            {"magsac", 0.90, 0.98},     // measured: 0.925, 1.0
                            {"gms", 0.88, 0.76},        // measured: 0.903, 0.789
                            {"lsc", 0.86, 0.98},        // measured: 0.886, 1.0
                            {"local_gsc", 0.85, 0.97},  // measured: 0.875, 0.997
                            {"guided", 0.91, 0.97},     // measured: 0.930, 0.997
                            {"best", 0.90, 0.97},       // measured: 0.924, 0.997
                        });
}

TEST(RealData, GrafFiltersMeetTheirFloors) {
  SIFT_HULL_REQUIRE_DATA(dir, "oxford_affine_graf");
  const FilterScores all = scoreFilter(graf().truth, filterRatio(graf().putative));
  EXPECT_GT(all.wrong_putative, 100u);  // measured: 137 of 1179
  expectFloors(graf(), {
                           {"ratio", 0.86, 0.98},      // measured: 0.884, 1.0
                           {"gsc", 0.91, 0.97},        // measured: 0.939, 0.993
                           {"ransac", 0.96, 0.89},     // measured: 0.985, 0.917
                           {"magsac", 0.96, 0.91},     // measured: 0.981, 0.934
                           {"gms", 0.92, 0.85},        // measured: 0.947, 0.870
                           {"lsc", 0.93, 0.98},        // measured: 0.957, 1.0
                           {"local_gsc", 0.92, 0.97},  // measured: 0.950, 0.994
                           {"guided", 0.97, 0.97},     // measured: 0.990, 0.990
                           {"best", 0.97, 0.97},       // measured: 0.990, 0.991
                       });
}

TEST(RealData, GrafOneToFourBestIsAheadOfMagsac) {
  SIFT_HULL_REQUIRE_DATA(dir, "oxford_affine_graf");
  MatchConfig matching;
  matching.ratio = 0.8;
  const LabelledMatches pair = matchPlanarPair(dir + "/img1.png", dir + "/img4.png",
                                               dir + "/H1to4p", SiftConfig(), matching);
  const FilterScores best = scoreByName(pair, "best"), magsac = scoreByName(pair, "magsac");
  // Measured (seed 0): best (vote_ransac) precision 1.0, recall 0.933; magsac 0.857, 0.640
  // (F1 0.966, 0.733).
  EXPECT_GE(best.precision(), 0.95);
  EXPECT_GE(best.recall(), 0.85);
  EXPECT_GE(best.f1() - magsac.f1(), 0.1);
}

// ---- the match command --------------------------------------------------------------------------

/// A 12-view scene at 320x240 written into a temporary directory, once.
const std::string& writtenScene() {
  static const std::string directory = [] {
    SceneConfig config;
    config.views = 12;
    config.width_px = 320;
    config.height_px = 240;
    const std::string dir = test::temporaryDirectory() + "/scene";
    writeScene(dir, config, renderScene(config));
    return dir;
  }();
  return directory;
}

void expectScoredRun(const nlohmann::json& run) {
  for (const char* key : {"kept", "time_ms", "precision", "recall", "f1", "mismatches_removed"}) {
    EXPECT_TRUE(run.contains(key)) << key << " in " << run.dump();
  }
  ASSERT_TRUE(run["precision"].is_number()) << run.dump();
  EXPECT_GT(run["precision"].get<double>(), 0.5);
  EXPECT_GT(run["kept"].get<int>(), 0);
}

TEST(MatchCommand, ScoresFiltersOnASceneAndDrawsFigures) {
  const std::string scene = writtenScene();
  const std::string out_dir = test::temporaryDirectory();
  std::string out, err;
  ASSERT_EQ(test::runProgram(
                "match " + scene + "/view_0000.png " + scene + "/view_0001.png" + " --gt-scene " +
                    scene + " --json --filter gsc --filter epipolar+gsc --out-image " + out_dir +
                    "/matches.png --out-histograms " + out_dir + "/histograms.png",
                &out, &err),
            0)
      << err;
  const nlohmann::json result = nlohmann::json::parse(out);
  EXPECT_GT(result["putative"].get<int>(), 50);  // measured: 141
  ASSERT_EQ(result["filters"].size(), 2u) << out;
  expectScoredRun(result["filters"]["gsc"]);
  expectScoredRun(result["filters"]["epipolar+gsc"]);
  EXPECT_FALSE(cv::imread(out_dir + "/matches.png").empty());
  EXPECT_FALSE(cv::imread(out_dir + "/histograms.png").empty());
}

TEST(MatchCommand, FilterFlagsAreTheSettingNamesAndOldNamesAreRefused) {
  const std::string scene = writtenScene();
  const std::string match = "match " + scene + "/view_0000.png " + scene + "/view_0001.png" +
                            " --gt-scene " + scene +
                            " --json --filter gsc --filter ransac --filter magsac --filter gms ";
  std::string out, err;
  ASSERT_EQ(test::runProgram(match + "--gsc-max-histogram-distance 1.5 --ransac-max-epipolar-px 3 "
                                     "--magsac-max-epipolar-px 3 --gms-grid-cells 10 "
                                     "--gms-with-rotation --gms-with-scale --backend flann "
                                     "--max-descriptor-distance 300 --sigma-px 1.5",
                             &out, &err),
            0)
      << err;
  const nlohmann::json result = nlohmann::json::parse(out);  // stdout holds it alone
  // Histograms are at most sqrt(2) apart: 1.5 keeps every putative.
  EXPECT_EQ(result["filters"]["gsc"]["kept"], result["putative"]);
  EXPECT_GT(result["filters"]["magsac"]["kept"].get<int>(), 20);
  for (const char* old : {"--gsc-max-distance 0", "--ransac-px 3", "--gms-cells 10", "--sigma 1.5",
                          "--max-histogram-distance 0", "--grid-cells 10"}) {
    EXPECT_EQ(test::runProgram(match + old, &out, &err), 2) << old;
    EXPECT_NE(err.find("unknown option"), std::string::npos) << err;
  }
}

TEST(MatchCommand, MissingImageExitsWithOne) {
  const std::string scene = writtenScene();
  std::string out, err;
  EXPECT_EQ(
      test::runProgram("match " + scene + "/absent.png " + scene + "/view_0001.png", &out, &err),
      1);
  EXPECT_NE(err.find(scene + "/absent.png"), std::string::npos) << err;
}

TEST(MatchCommand, UnknownOptionExitsWithTwo) {
  const std::string scene = writtenScene();
  std::string out, err;
  EXPECT_EQ(test::runProgram(
                "match " + scene + "/view_0000.png " + scene + "/view_0001.png --no-such-option",
                &out, &err),
            2);
  EXPECT_NE(err.find("--no-such-option"), std::string::npos) << err;
}

}  // namespace
}  // namespace sift_hull
