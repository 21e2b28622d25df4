// The voted LO-RANSAC filter (vote_ransac, today's best) on synthetic putatives with known
// inliers (a 3D scene and a similarity, 30 % and 60 % outliers), rotation and zoom of the right
// image, two motions, pure noise, tiny and degenerate inputs. Its models are tested in
// test_two_view_models; its time is measured by `sift_hull_bench bench-filters`, not here.
#include <gtest/gtest.h>

#include <Eigen/Dense>
#include <Eigen/Geometry>
#include <cmath>
#include <iostream>
#include <random>

#include "filters/motion_frame.h"
#include "sift_hull/eval/match_evaluation.h"
#include "sift_hull/features/labelled_matches.h"
#include "sift_hull/filters/filter.h"
#include "sift_hull/filters/two_view_models.h"
#include "sift_hull/filters/vote_ransac.h"
#include "sift_hull/geometry/camera.h"
#include "sift_hull/synthetic/synthetic_matches.h"
#include "synthetic_putatives.h"
#include "two_view_scene.h"

namespace sift_hull {
namespace {

using test::differing;
using test::pairsOf;
using test::sceneMatches;
using test::transformRight;
using test::twoCameras;
using test::twoMotions;

/// The share of the true matches that the exact F keeps at the filter's threshold: with 0.3 px of
/// noise on each coordinate some true matches lie beyond 1 px, so no filter can reach recall 1.
double oracleRecall(const LabelledMatches& input, double threshold_px) {
  TwoViewModel truth;
  truth.matrix = twoCameras().F();
  size_t correct = 0, within = 0;
  for (size_t m = 0; m < input.truth.size(); ++m) {
    if (input.truth[m] != MatchTruth::kCorrect) continue;
    const cv::Point2f &a = input.putative.left(m).pt, &b = input.putative.right(m).pt;
    ++correct;
    within += modelResidual(truth, a.x, a.y, b.x, b.y) <= threshold_px;
  }
  return double(within) / double(correct);
}

TEST(VoteRansac, SeparatesASceneAtThirtyAndSixtyPercentOutliers) {
  // Ten scenes each: the recall is measured against what the exact F keeps (the oracle), since
  // the found F differs from it by the noise of the fit (on 100 scenes at 60 % outliers the
  // largest shortfall was 0.042, the mean 0.004).
  const FilterConfigs configs;
  const auto filter = makeFilter("vote_ransac", configs);
  for (double outliers : {0.3, 0.6}) {
    double shortfall_sum = 0.0;
    const unsigned first = 41, count = 10;
    for (unsigned seed = first; seed < first + count; ++seed) {
      const LabelledMatches input = sceneMatches(600, outliers, seed, 0.3);
      const FilterScores s = scoreFilter(input.truth, filter->apply(input.putative));
      const double oracle = oracleRecall(input, configs.magsac.max_epipolar_px);
      std::cout << "scene " << seed << ", " << outliers << " outliers: P " << s.precision() << " R "
                << s.recall() << " (exact F: " << oracle << ")\n";
      EXPECT_GE(s.recall(), oracle - 0.07) << outliers << " seed " << seed;
      EXPECT_GE(s.precision(), 0.97) << outliers << " seed " << seed;
      shortfall_sum += oracle - s.recall();
    }
    EXPECT_LE(shortfall_sum / count, 0.015) << outliers;
  }
}

TEST(VoteRansac, ASimilarityPairIsFittedByTheHomography) {
  for (double outliers : {0.3, 0.6}) {
    const LabelledMatches input = test::synthetic(outliers, 23);
    const FilterConfigs configs;
    const std::vector<TwoViewModel> motions =
        voteRansacMotions(input.putative, {configs.vote_ransac, configs.guided, configs.magsac});
    ASSERT_EQ(motions.size(), 1u) << outliers;
    EXPECT_TRUE(motions[0].homography);
    const FilterScores s =
        scoreFilter(input.truth, makeFilter("vote_ransac", configs)->apply(input.putative));
    EXPECT_GE(s.recall(), 0.97) << outliers;
    EXPECT_GE(s.precision(), 0.97) << outliers;
  }
}

/// How far a match's SIFT frame lies within a motion's bounds (motion_frame.h): the smaller of
/// its turn's margin to kMaxTurnFromMotionDeg (deg) and its scale's to kMaxOctavesFromMotion
/// (octaves, counted as 10 deg each); negative beyond a bound. `signed_margin` false: its
/// absolute value, the distance to the nearer bound.
double frameEdgeDistance(const detail::MotionFrame& frame, const cv::KeyPoint& l,
                         const cv::KeyPoint& r, bool signed_margin = false) {
  double turn = std::fmod(double(r.angle) - double(l.angle) - frame.turn_deg + 720.0, 360.0);
  turn = std::min(turn, 360.0 - turn);
  const double octaves = std::abs(std::log2(double(r.size) / double(l.size)) - frame.log2_scale);
  const double margin = std::min(detail::kMaxTurnFromMotionDeg - turn,
                                 10.0 * (detail::kMaxOctavesFromMotion - octaves));
  return signed_margin ? margin : std::abs(margin);
}

TEST(VoteRansac, KeepsWhatThePlainReferenceKeepsUnderItsMotions) {
  // The reference: a match is kept when a motion explains it within its threshold and, for a
  // fundamental matrix, its SIFT frame agrees with the scene's true one (the cameras' roll, the
  // median scale change of the true matches). The filter estimates that frame from its vote
  // (the medians of its windows), so a match may differ only at a threshold's or a frame bound's
  // edge. Whether a mismatch of a random frame falls in the epipolar band here is chance; the
  // next case places them there.
  const LabelledMatches input = sceneMatches(500, 0.4, 43, 0.3);
  const FilterConfigs c;
  const std::vector<TwoViewModel> motions =
      voteRansacMotions(input.putative, {c.vote_ransac, c.guided, c.magsac});
  const FilterResult result = makeFilter("vote_ransac", c)->apply(input.putative);
  ASSERT_FALSE(motions.empty());
  std::vector<double> true_scales;
  for (size_t m = 0; m < input.truth.size(); ++m) {
    if (input.truth[m] != MatchTruth::kCorrect) continue;
    true_scales.push_back(
        std::log2(double(input.putative.right(m).size) / double(input.putative.left(m).size)));
  }
  std::nth_element(true_scales.begin(), true_scales.begin() + long(true_scales.size() / 2),
                   true_scales.end());
  detail::MotionFrame truth;
  truth.turn_deg = float(0.25 * 180.0 / M_PI);  // the roll of two_view_scene.h's cameras
  truth.log2_scale = float(true_scales[true_scales.size() / 2]);
  size_t borderline = 0;
  for (size_t m = 0; m < input.truth.size(); ++m) {
    const cv::KeyPoint &l = input.putative.left(m), &r = input.putative.right(m);
    const cv::Point2f &a = l.pt, &b = r.pt;
    bool keep = false;
    double nearest_edge = INFINITY;
    for (const TwoViewModel& motion : motions) {
      const double limit = motion.homography ? c.guided.max_transfer_px : c.magsac.max_epipolar_px;
      const double rad = modelResidual(motion, a.x, a.y, b.x, b.y);
      const bool agrees = motion.homography || frameEdgeDistance(truth, l, r, true) >= 0.0;
      keep = keep || (rad <= limit && agrees);
      nearest_edge = std::min(nearest_edge, std::abs(rad - limit));
    }
    if (bool(result.keep[m]) != keep) {
      ++borderline;
      EXPECT_TRUE(nearest_edge < 1e-3 || frameEdgeDistance(truth, l, r) < 5.0)
          << "match " << m << " differs away from its threshold and the frame's bounds";
    }
  }
  EXPECT_LE(borderline, 2u);  // float against double residuals, an estimated frame
}

TEST(VoteRansac, DropsMismatchesOnTheEpipolarLinesWhoseFrameDisagrees) {
  // Mismatches placed on their epipolar lines: F explains each; the ones whose SIFT patch turns a
  // half turn against the scene's, or changes scale eightfold, are dropped, the ones whose frame
  // agrees are kept (nothing but the frame tells them from correct matches), and every correct
  // match, turned by up to 60 degrees against the rest, is kept.
  LabelledMatches input = sceneMatches(400, 0.0, 53, 0.0);
  const Eigen::Matrix3d F = twoCameras().F();
  std::mt19937 random(54);
  std::uniform_real_distribution<double> along(20.0, 620.0), turn(-60.0, 60.0);
  PutativeMatches& p = input.putative;
  for (size_t m = 0; m < 400; m += 4)
    p.right_keypoints[m].angle =  // correct, turned by perspective
        std::fmod(float(p.right_keypoints[m].angle + turn(random) + 360.0), 360.f);
  const size_t correct = p.matches.size();
  for (size_t k = 0; k < 120; ++k) {  // a right point elsewhere on the left point's epipolar line
    const cv::KeyPoint l = p.left_keypoints[k];
    const Eigen::Vector3d line = F * Eigen::Vector3d(l.pt.x, l.pt.y, 1.0);
    const double x = along(random), y = -(line.x() * x + line.z()) / line.y();
    cv::KeyPoint r = p.right_keypoints[k];
    r.pt = cv::Point2f(float(x), float(y));
    if (k % 3 == 1) r.angle = std::fmod(r.angle + 180.f, 360.f);  // turned a half turn
    if (k % 3 == 2) r.size = r.size * 8.f;                        // three octaves larger
    p.left_keypoints.push_back(l), p.right_keypoints.push_back(r);
    p.matches.emplace_back(int(p.left_keypoints.size() - 1), int(p.right_keypoints.size() - 1),
                           0.f);
    input.truth.push_back(MatchTruth::kWrong);
  }
  const FilterResult result = makeFilter("best", FilterConfigs())->apply(p);
  size_t kept_correct = 0, kept_agreeing = 0, kept_disagreeing = 0;
  for (size_t m = 0; m < p.matches.size(); ++m) {
    if (m < correct) {
      kept_correct += result.keep[m];
    } else if ((m - correct) % 3 == 0) {
      kept_agreeing += result.keep[m];
    } else {
      kept_disagreeing += result.keep[m];
    }
  }
  EXPECT_EQ(kept_correct, correct);
  EXPECT_GE(kept_agreeing, 36u);  // of 40: F explains them, their frame agrees
  EXPECT_EQ(kept_disagreeing, 0u);
}

TEST(VoteRansac, KeepsOnePlaceOnTheLineForEachRightKeypoint) {
  // A right keypoint is the image of one place. Left points elsewhere on the epipolar line of a
  // correct match's right keypoint, matched to that keypoint with the same frame: F explains
  // both, so the smaller descriptor distance decides. A second orientation at the correct left
  // point's place (as SIFT makes them) is the same place and stays beside it.
  LabelledMatches input = sceneMatches(400, 0.0, 57, 0.0);
  PutativeMatches& p = input.putative;
  for (cv::DMatch& match : p.matches) match.distance = 100.f;
  const Eigen::Matrix3d F = twoCameras().F();
  std::mt19937 random(58);
  std::uniform_real_distribution<double> along(20.0, 620.0);
  const size_t correct = p.matches.size(), shared = 60;
  for (size_t k = 0; k < shared; ++k) {  // match k pairs left and right keypoint k
    const cv::KeyPoint& q = p.right_keypoints[k];
    cv::KeyPoint l = p.left_keypoints[k];
    float distance = 120.f;
    if (k % 3 == 2) {
      l.angle = std::fmod(l.angle + 40.f, 360.f);  // another orientation at the same place
    } else {
      const Eigen::Vector3d line = F.transpose() * Eigen::Vector3d(q.pt.x, q.pt.y, 1.0);
      double x = along(random);
      while (std::abs(x - l.pt.x) < 40.0) x = along(random);
      l.pt = cv::Point2f(float(x), float(-(line.x() * x + line.z()) / line.y()));
      distance = k % 3 == 0 ? 200.f : 50.f;  // farther than the correct match, or closer
    }
    p.left_keypoints.push_back(l);
    p.matches.emplace_back(int(p.left_keypoints.size() - 1), int(k), distance);
    input.truth.push_back(k % 3 == 2 ? MatchTruth::kCorrect : MatchTruth::kWrong);
  }
  const FilterResult result = makeFilter("best", FilterConfigs())->apply(p);
  for (size_t k = 0; k < shared; ++k) {
    const size_t added = correct + k;
    if (k % 3 == 0) {
      EXPECT_FALSE(result.keep[added]) << k;
      EXPECT_TRUE(result.keep[k]) << k;
    } else if (k % 3 == 1) {  // the closer descriptor wins, even against the true place
      EXPECT_TRUE(result.keep[added]) << k;
      EXPECT_FALSE(result.keep[k]) << k;
    } else {
      EXPECT_TRUE(result.keep[added]) << k;
      EXPECT_TRUE(result.keep[k]) << k;
    }
  }
  size_t kept_rest = 0;
  for (size_t m = shared; m < correct; ++m) kept_rest += result.keep[m];
  EXPECT_EQ(kept_rest, correct - shared);
}

TEST(VoteRansac, SameDecisionsAfterRotatingTheRightImage) {
  // The votes are found from the data, so a rotation moves nothing the residuals see.
  const LabelledMatches input = sceneMatches(600, 0.3, 47, 0.3);
  const auto filter = makeFilter("best", FilterConfigs());
  const FilterResult before = filter->apply(input.putative);
  for (double deg : {90.0, 37.0, -120.0}) {
    const FilterResult after = filter->apply(transformRight(input.putative, deg, 1.0));
    std::cout << "best rotated " << deg << ": " << differing(before, after) << " of "
              << input.truth.size() << " differ\n";
    EXPECT_LE(differing(before, after), input.truth.size() / 100) << deg;  // measured: 0
  }
}

TEST(VoteRansac, SameDecisionsAfterZoomingTheRightImageWhereNoiseAllows) {
  // The thresholds are pixels, so a zoom scales the right image's noise against them (0.3 px
  // noise zoomed 1.6x drops 11 % of the inliers at 1 px, as it would for MAGSAC): with exact
  // inliers, zooming and turning must change no decision but the rare outlier at the edge.
  const LabelledMatches input = sceneMatches(600, 0.3, 71, 0.0);
  const auto filter = makeFilter("best", FilterConfigs());
  const FilterResult before = filter->apply(input.putative);
  EXPECT_GE(scoreFilter(input.truth, before).recall(), 0.99);
  for (const auto& [deg, scale] : {std::pair{25.0, 1.6}, {-70.0, 0.5}, {0.0, 2.5}}) {
    const FilterResult after = filter->apply(transformRight(input.putative, deg, scale));
    std::cout << "best rotated " << deg << " zoomed " << scale << ": " << differing(before, after)
              << " of " << input.truth.size() << " differ\n";
    EXPECT_LE(differing(before, after), input.truth.size() / 100) << deg << " " << scale;
  }
}

TEST(VoteRansac, AZoomKeepsTheMatchesALeftPixelOfErrorAllows) {
  // Points located to 0.6 px (each coordinate's noise) in the left image land 2.5 times as far
  // off in a right image zoomed 2.5 times: 13 % of them beyond 3 px. Measured in the
  // homography's local scale (guided_tolerance_scale "model", the default) they are all within
  // the tolerance; in pixels they are lost, as MAGSAC would lose them.
  SyntheticMatchConfig config;
  config.inliers = 600;
  config.outlier_fraction = 0.3;
  config.rotation_deg = 0.0, config.scale = 1.0, config.shift_px = 0.0;
  config.position_noise_px = 0.6;
  config.seed = 29;
  LabelledMatches input = syntheticMatches(config);
  input.putative = transformRight(input.putative, 30.0, 2.5);
  FilterConfigs configs;
  const FilterScores model =
      scoreFilter(input.truth, makeFilter("best", configs)->apply(input.putative));
  configs.guided.tolerance_scale = "pixels";
  const FilterScores pixels =
      scoreFilter(input.truth, makeFilter("best", configs)->apply(input.putative));
  std::cout << "zoom 2.5: recall " << model.recall() << " (model) against " << pixels.recall()
            << " (pixels), precision " << model.precision() << " against " << pixels.precision()
            << "\n";
  EXPECT_GE(model.recall(), 0.99);
  EXPECT_LE(pixels.recall(), 0.92);
  EXPECT_GE(model.precision(), 0.99);
  configs.guided.tolerance_scale = "metres";
  EXPECT_THROW(makeFilter("best", configs), std::invalid_argument);
}

TEST(VoteRansac, FindsBothMotionsWhereOneModelFails) {
  const LabelledMatches input = twoMotions();
  const FilterScores s =
      scoreFilter(input.truth, makeFilter("vote_ransac", FilterConfigs())->apply(input.putative));
  std::cout << "two motions: R " << s.recall() << " P " << s.precision() << "\n";
  EXPECT_GE(s.recall(), 0.95);
  EXPECT_GE(s.precision(), 0.97);
}

TEST(VoteRansac, TwoMotionsCloseTogetherKeepTheirOwnMatches) {
  // Two similarities over the same image (20 and 24 deg, 1.2x), the second shifted 8 px to the
  // right: the matches of each lie within three times the other's 3 px threshold over much of
  // the image, where each motion's refinement against all matches looks. Both motions must be
  // found and keep their matches (a translation alone would not do: H and a shifted H share one
  // fundamental matrix, which then explains both).
  LabelledMatches a = test::synthetic(0.0, 13), b = test::synthetic(0.0, 17, 24.0, 1.2);
  const int offset = static_cast<int>(a.putative.left_keypoints.size());
  for (size_t m = 0; m < b.putative.matches.size(); ++m) {
    a.putative.left_keypoints.push_back(b.putative.left(m));
    a.putative.right_keypoints.push_back(b.putative.right(m));
    a.putative.right_keypoints.back().pt.x += 8.f;
    a.putative.matches.emplace_back(offset + int(m), offset + int(m), 0.f);
    a.truth.push_back(b.truth[m]);
  }
  injectMismatches(&a, 0.3, 19);
  const FilterConfigs configs;
  const std::vector<TwoViewModel> motions =
      voteRansacMotions(a.putative, {configs.vote_ransac, configs.guided, configs.magsac});
  ASSERT_EQ(motions.size(), 2u);
  const FilterResult result = makeFilter("vote_ransac", configs)->apply(a.putative);
  for (int object = 0; object < 2; ++object) {
    size_t correct = 0, kept = 0;
    for (size_t m = 0; m < a.truth.size(); ++m) {
      const bool mine =
          object == 0 ? m < size_t(offset) : (m >= size_t(offset) && m < 2 * size_t(offset));
      if (!mine || a.truth[m] != MatchTruth::kCorrect) continue;
      ++correct;
      kept += result.keep[m];
    }
    std::cout << "object " << object << ": " << kept << " of " << correct << " kept\n";
    EXPECT_GE(double(kept), 0.95 * double(correct)) << object;
  }
  EXPECT_GE(scoreFilter(a.truth, result).precision(), 0.97);
}

TEST(VoteRansac, PureNoiseKeepsAlmostNothing) {
  LabelledMatches input = test::synthetic(0.0, 53);
  input.putative.matches.resize(1), input.truth.resize(1);
  injectMismatches(&input, 0.998, 59);  // about 500 random pairs
  const FilterResult result = makeFilter("vote_ransac", FilterConfigs())->apply(input.putative);
  EXPECT_LE(result.keptCount(), input.truth.size() / 50);
}

TEST(VoteRansac, BestIsVoteRansacAndSeedsRepeat) {
  const LabelledMatches input = sceneMatches(400, 0.3, 61, 0.3);
  FilterConfigs configs;
  configs.magsac.seed = 4;
  const FilterResult a = makeFilter("best", configs)->apply(input.putative);
  EXPECT_EQ(makeFilter("vote_ransac", configs)->apply(input.putative).keep, a.keep);
  EXPECT_EQ(makeFilter("best", configs)->apply(input.putative).keep, a.keep);
}

TEST(VoteRansac, TinyAndDegenerateInputsKeepNothingWithoutThrowing) {
  const auto filter = makeFilter("vote_ransac", FilterConfigs());
  for (size_t n : {0u, 1u, 7u, 19u}) {
    LabelledMatches input = test::synthetic(0.0, 37);
    input.putative.matches.resize(std::min(n, input.putative.matches.size()));
    EXPECT_EQ(filter->apply(input.putative).keptCount(), 0u) << n << " matches";
  }
  PutativeMatches same;  // every match at one point: no motion can be fitted
  for (int i = 0; i < 50; ++i) {
    same.left_keypoints.emplace_back(cv::Point2f(5, 5), 4.f, 0.f);
    same.right_keypoints.emplace_back(cv::Point2f(9, 9), 4.f, 0.f);
    same.matches.emplace_back(i, i, 0.f);
  }
  EXPECT_NO_THROW(filter->apply(same));
  LabelledMatches odd = sceneMatches(200, 0.3, 67, 0.3);
  for (size_t k = 0; k < odd.putative.left_keypoints.size(); k += 3) {
    odd.putative.left_keypoints[k].angle = -1.f;  // no orientation: no vote
    odd.putative.right_keypoints[k].size = 0.f;
  }
  odd.putative.left_keypoints[1].pt.x = NAN;
  odd.putative.right_keypoints[2].pt.y = 1e30f;
  const FilterResult result = filter->apply(odd.putative);
  EXPECT_FALSE(result.keep[1]);
  EXPECT_TRUE(std::isnan(result.score[1]));
  EXPECT_GE(scoreFilter(odd.truth, result).recall(), 0.95);
}

TEST(VoteRansac, RejectsInvalidConfigs) {
  std::vector<FilterConfigs> bad(6);
  bad[0].vote_ransac.max_angle_deg = 0.0;
  bad[1].vote_ransac.max_angle_deg = 181.0;
  bad[2].vote_ransac.max_scale_ratio = 1.0;
  bad[3].vote_ransac.max_scale_ratio = INFINITY;
  bad[4].vote_ransac.max_fit_points = 15;
  bad[5].vote_ransac.max_angle_deg = NAN;
  for (const FilterConfigs& configs : bad) EXPECT_THROW(validate(configs), std::invalid_argument);
}

TEST(MotionFrame, TurnsWrapAroundTheCircleAndUnknownsAgree) {
  const detail::MotionFrame frame = detail::motionFrame(350.f, 0.f);  // turned by -10 deg
  detail::MatchFrames m;
  m.resize(9);
  m.set(0, 10.f, 4.f, 359.f, 4.f);     // turn -11 deg: 1 deg from the motion's
  m.set(1, 350.f, 4.f, 60.f, 4.f);     // turn +70 deg across 0: 80 deg from it
  m.set(2, 0.f, 4.f, 200.f, 4.f);      // a half turn: 150 deg from it
  m.set(3, 10.f, 4.f, 0.f, 17.f);      // scale 4.25: beyond two octaves
  m.set(4, 10.f, 4.f, 0.f, 0.9f);      // scale 0.225: beyond two octaves below
  m.set(5, -1.f, 4.f, 200.f, 4.f);     // no orientation (OpenCV's -1): the turn is unknown
  m.set(6, NAN, 4.f, 0.f, 0.f);        // NaN angle, no size: nothing known
  m.set(7, 10.f, 0.f, 0.f, 1e30f);     // no left size: the scale is unknown
  m.set(8, 10.f, 1e-30f, 0.f, 1e30f);  // an infinite ratio: beyond any bound
  const bool expected[] = {true, true, false, false, false, true, true, true, false};
  for (size_t k = 0; k < 9; ++k) {
    EXPECT_EQ(detail::frameAgrees(frame, m.turn_deg[k], m.scale_ratio[k]), expected[k]) << k;
  }
  // An unknown frame (the vote sampled from all): every match agrees.
  for (size_t k = 0; k < 9; ++k) {
    EXPECT_TRUE(detail::frameAgrees(detail::MotionFrame(), m.turn_deg[k], m.scale_ratio[k])) << k;
  }
}

}  // namespace
}  // namespace sift_hull