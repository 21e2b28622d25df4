#include "match_eval.h"

#include <chrono>
#include <cmath>

#include "sift_hull/eval/match_evaluation.h"
#include "sift_hull/features/labelled_matches.h"
#include "sift_hull/filters/filter_result.h"
#include "sift_hull/io/ground_truth_files.h"

namespace sift_hull {
namespace cli {

PairTruth disparityTruth(const std::string& path, double scale) {
  const cv::Mat disparity = readDisparity(path, scale);
  return {"disparity",
          [disparity](const PutativeMatches& input) { return judgeByDisparity(input, disparity); }};
}

PairTruth homographyTruth(const std::string& path) {
  const Eigen::Matrix3d H = readHomography(path);
  return {"homography", [H](const PutativeMatches& input) { return judgeByHomography(input, H); }};
}

PairTruth sceneTruth(const DepthView& left, const DepthView& right) {
  return {"scene", [left, right](const PutativeMatches& input) {
            return judgeBySceneDepth(input, left, right);
          }};
}

FilterRun timedRun(const MatchFilter& filter, const PutativeMatches& input) {
  const auto start = std::chrono::steady_clock::now();
  FilterResult result = filter.apply(input);
  const auto stop = std::chrono::steady_clock::now();
  return {filter.name(), std::move(result),
          std::chrono::duration<double, std::milli>(stop - start).count()};
}

nlohmann::json numberOrNull(double value) {
  return std::isnan(value) ? nlohmann::json(nullptr) : nlohmann::json(value);
}

nlohmann::json filterRunJson(const FilterRun& run, const std::vector<MatchTruth>* truth) {
  nlohmann::json json = {{"kept", run.result.keptCount()},
                         {"time_ms", run.time_ms},
                         {"precision", nullptr},
                         {"recall", nullptr},
                         {"f1", nullptr},
                         {"mismatches_removed", nullptr}};
  if (truth == nullptr) return json;
  const FilterScores scores = scoreFilter(*truth, run.result);
  json["precision"] = numberOrNull(scores.precision());
  json["recall"] = numberOrNull(scores.recall());
  json["f1"] = numberOrNull(scores.f1());
  json["mismatches_removed"] = scores.mismatchesRemoved();
  json["correct_kept"] = scores.correct_kept;
  json["wrong_kept"] = scores.wrong_kept;
  json["unknown_kept"] = scores.unknown_kept;
  return json;
}

nlohmann::json truthJson(const std::string& kind, const std::vector<MatchTruth>& truth) {
  size_t counts[3] = {0, 0, 0};
  for (MatchTruth each : truth) ++counts[static_cast<int>(each)];
  return {{"kind", kind}, {"correct", counts[0]}, {"wrong", counts[1]}, {"unknown", counts[2]}};
}

}  // namespace cli
}  // namespace sift_hull
