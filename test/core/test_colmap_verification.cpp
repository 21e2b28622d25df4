// COLMAP's two-view verification run by its program (colmap_verification.h): on a warped pair
// with exact ground truth when the program is installed, and a missing program named.
#include <gtest/gtest.h>

#include <cmath>

#include "sift_hull/eval/match_evaluation.h"
#include "sift_hull/features/sift.h"
#include "sift_hull/filters/colmap_verification.h"
#include "sift_hull/filters/filter.h"
#include "sift_hull/synthetic/warped_pairs.h"

namespace sift_hull {
namespace {

TEST(ColmapVerification, AMissingProgramIsNamed) {
  std::string why_not;
  EXPECT_FALSE(colmapAvailable("sift_hull_no_such_program", &why_not));
  EXPECT_NE(why_not.find("not found on PATH"), std::string::npos) << why_not;
  PutativeMatches input;
  input.left_image_size = input.right_image_size = cv::Size(64, 48);
  ColmapConfig config;
  config.program = "sift_hull_no_such_program";
  try {
    filterColmap(input, config);
    ADD_FAILURE() << "a missing program gave a result";
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find("sift_hull_no_such_program"), std::string::npos)
        << e.what();
  }
}

TEST(ColmapVerification, KeepsTheMatchesOfOneMotionAndNoneWithoutAPosition) {
  std::string why_not;
  if (!colmapAvailable("colmap", &why_not)) GTEST_SKIP() << why_not;
  const WarpedPair pair = rotationZoomPair(20.0, 1.2);
  PutativeMatches input = matchImages(pair.left, pair.right, SiftConfig(), MatchConfig());
  ASSERT_GT(input.matches.size(), 100u);
  input.left_keypoints.emplace_back(cv::Point2f(NAN, 5.0f), 3.0f);
  input.matches.emplace_back(static_cast<int>(input.left_keypoints.size() - 1), 0, 0.0f);
  const std::vector<MatchTruth> truth = judgeByMotions(input, pair);
  const FilterResult result = filterColmap(input, ColmapConfig());
  ASSERT_EQ(result.keep.size(), input.matches.size());
  const FilterScores scores = scoreFilter(truth, result);
  EXPECT_GT(scores.precision(), 0.95);
  EXPECT_GT(scores.recall(), 0.9);
  EXPECT_FALSE(result.keep.back());
  EXPECT_TRUE(std::isnan(result.score.back()));
  // By name, with the same seed: the same verdicts.
  EXPECT_EQ(makeFilter("colmap", FilterConfigs())->apply(input).keep, result.keep);
}

}  // namespace
}  // namespace sift_hull
