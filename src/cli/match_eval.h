#pragma once

#include <functional>
#include <nlohmann/json.hpp>
#include <optional>
#include <string>
#include <vector>

#include "sift_hull/eval/match_evaluation.h"
#include "sift_hull/features/labelled_matches.h"
#include "sift_hull/filters/filter.h"
#include "sift_hull/filters/filter_result.h"
#include "sift_hull/pipeline/pair_pipeline.h"

namespace sift_hull {
namespace cli {

/// Ground truth for a pair: a judge of putative matches and the name of its kind.
struct PairTruth {
  std::string kind;  ///< "disparity", "homography" or "scene"
  std::function<std::vector<MatchTruth>(const PutativeMatches&)> judge;
};

PairTruth disparityTruth(const std::string& path, double scale);
PairTruth homographyTruth(const std::string& path);
PairTruth sceneTruth(const DepthView& left, const DepthView& right);

/// One filter applied once, with its wall-clock time (what runPair returns per filter).
using FilterRun = FilterVerdicts;

FilterRun timedRun(const MatchFilter& filter, const PutativeMatches& input);

/// {"kept", "time_ms", "precision", "recall", "f1", "mismatches_removed", ...}; the scores are
/// null without ground truth.
nlohmann::json filterRunJson(const FilterRun& run, const std::vector<MatchTruth>* truth);

/// {"kind", "correct", "wrong", "unknown"} of the putative matches.
nlohmann::json truthJson(const std::string& kind, const std::vector<MatchTruth>& truth);

/// A number, or null when it is NaN.
nlohmann::json numberOrNull(double value);

}  // namespace cli
}  // namespace sift_hull
