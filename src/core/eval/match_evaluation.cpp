#include "sift_hull/eval/match_evaluation.h"

#include <cmath>
#include <fstream>
#include <opencv2/imgcodecs.hpp>
#include <sstream>
#include <stdexcept>

#include "sift_hull/io/ground_truth_files.h"
#include "sift_hull/io/images.h"

namespace sift_hull {
namespace {

Eigen::Vector2d position(const cv::KeyPoint& keypoint) { return {keypoint.pt.x, keypoint.pt.y}; }

/// Applies `judge` to every match with finite coordinates; the others are wrong.
template <typename Judge>
std::vector<MatchTruth> judgeEach(const PutativeMatches& input, Judge judge) {
  std::vector<MatchTruth> truth(input.matches.size(), MatchTruth::kWrong);
  for (size_t m = 0; m < input.matches.size(); ++m) {
    if (input.hasFinitePositions(m)) {
      truth[m] = judge(position(input.left(m)), position(input.right(m)));
    }
  }
  return truth;
}

double ratio(size_t numerator, size_t denominator) {
  return denominator == 0 ? NAN : static_cast<double>(numerator) / denominator;
}

}  // namespace

std::vector<MatchTruth> judgeByDisparity(const PutativeMatches& input, const cv::Mat& disparity_px,
                                         const TruthTolerances& tolerances) {
  if (disparity_px.type() != CV_32FC1) {
    throw std::invalid_argument("judgeByDisparity: disparity must be CV_32FC1");
  }
  if (input.left_image_size.area() > 0 && disparity_px.size() != input.left_image_size) {
    throw std::invalid_argument("the disparity map is " + std::to_string(disparity_px.cols) + "x" +
                                std::to_string(disparity_px.rows) + " but the left image is " +
                                std::to_string(input.left_image_size.width) + "x" +
                                std::to_string(input.left_image_size.height) +
                                ": it is not this image's ground truth");
  }
  return judgeEach(input, [&](const Eigen::Vector2d& left, const Eigen::Vector2d& right) {
    const long u = std::lround(left.x()), v = std::lround(left.y());
    if (u < 0 || v < 0 || u >= disparity_px.cols || v >= disparity_px.rows) {
      return MatchTruth::kUnknown;
    }
    const float d = disparity_px.at<float>(v, u);
    if (d <= 0.f) return MatchTruth::kUnknown;
    const bool on_row = std::abs(right.y() - left.y()) <= tolerances.max_row_error_px;
    const bool at_disparity =
        std::abs(right.x() - (left.x() - d)) <= tolerances.max_column_error_px;
    return on_row && at_disparity ? MatchTruth::kCorrect : MatchTruth::kWrong;
  });
}

std::vector<MatchTruth> judgeByHomography(const PutativeMatches& input,
                                          const Eigen::Matrix3d& H_right_left,
                                          const TruthTolerances& tolerances) {
  return judgeEach(input, [&](const Eigen::Vector2d& left, const Eigen::Vector2d& right) {
    const Eigen::Vector3d mapped = H_right_left * left.homogeneous();
    // H is defined up to scale (and sign): only a point mapped to infinity has no image.
    if (!(std::abs(mapped.z()) > 1e-12)) return MatchTruth::kWrong;
    const double error = (mapped.hnormalized() - right).norm();
    return error <= tolerances.max_homography_error_px ? MatchTruth::kCorrect : MatchTruth::kWrong;
  });
}

std::vector<MatchTruth> judgeBySceneDepth(const PutativeMatches& input, const DepthView& left,
                                          const DepthView& right,
                                          const TruthTolerances& tolerances) {
  return judgeEach(input, [&](const Eigen::Vector2d& left_px, const Eigen::Vector2d& right_px) {
    const TrueCorrespondence truth = trueCorrespondence(left, right, left_px);
    if (truth.visibility == Visibility::kBackground) return MatchTruth::kUnknown;
    if (truth.visibility != Visibility::kVisible) return MatchTruth::kWrong;
    const double error = (truth.pixel_b - right_px).norm();
    return error <= tolerances.max_scene_error_px ? MatchTruth::kCorrect : MatchTruth::kWrong;
  });
}

LabelledMatches matchRectifiedPair(const std::string& left_path, const std::string& right_path,
                                   const std::string& disparity_path, double disparity_scale,
                                   const SiftConfig& sift, const MatchConfig& matching) {
  LabelledMatches result;
  result.putative = matchImages(readImage(left_path), readImage(right_path), sift, matching);
  result.putative.F_right_left = rectifiedFundamentalMatrix();
  result.truth = judgeByDisparity(result.putative, readDisparity(disparity_path, disparity_scale));
  return result;
}

LabelledMatches matchPlanarPair(const std::string& left_path, const std::string& right_path,
                                const std::string& homography_path, const SiftConfig& sift,
                                const MatchConfig& matching) {
  LabelledMatches result;
  result.putative = matchImages(readImage(left_path), readImage(right_path), sift, matching);
  result.truth = judgeByHomography(result.putative, readHomography(homography_path));
  return result;
}

double FilterScores::precision() const { return ratio(correct_kept, correct_kept + wrong_kept); }

double FilterScores::recall() const { return ratio(correct_kept, correct_putative); }

double FilterScores::f1() const {
  const double p = precision(), r = recall();
  if (std::isnan(p) || std::isnan(r)) return NAN;
  return p + r > 0.0 ? 2.0 * p * r / (p + r) : 0.0;
}

FilterScores scoreFilter(const std::vector<MatchTruth>& truth, const FilterResult& result) {
  if (truth.size() != result.keep.size()) {
    throw std::invalid_argument("scoreFilter: ground truth and filter result differ in size");
  }
  FilterScores scores;
  scores.putative = truth.size();
  for (size_t m = 0; m < truth.size(); ++m) {
    const bool kept = result.keep[m] != 0;
    scores.kept += kept;
    size_t* putative = truth[m] == MatchTruth::kCorrect ? &scores.correct_putative
                       : truth[m] == MatchTruth::kWrong ? &scores.wrong_putative
                                                        : &scores.unknown_putative;
    size_t* kept_count = truth[m] == MatchTruth::kCorrect ? &scores.correct_kept
                         : truth[m] == MatchTruth::kWrong ? &scores.wrong_kept
                                                          : &scores.unknown_kept;
    *putative += 1;
    *kept_count += kept;
  }
  return scores;
}

}  // namespace sift_hull
