#pragma once

#include <optional>
#include <string>
#include <vector>

#include "match_options.h"
#include "sift_hull/eval/match_evaluation.h"
#include "sift_hull/features/labelled_matches.h"

namespace sift_hull {
namespace cli {

/// The real data root: $SIFT_HULL_DATA, else ../shared/data when it exists, else empty.
std::string defaultDataRoot();

/// A real image pair, its putative matches and their ground truth.
struct EvaluationPair {
  std::string name;
  LabelledMatches matches;
};

/// Middlebury Teddy (rectified; F of a rectified pair; disparity ground truth). Empty, with
/// `why_not` set, when the data set is absent.
std::optional<EvaluationPair> teddyPair(const std::string& data_root, const MatchOptions& options,
                                        std::string* why_not);

/// Oxford graf 1-N (homography ground truth, no calibration).
std::optional<EvaluationPair> grafPair(const std::string& data_root, int n,
                                       const MatchOptions& options, std::string* why_not);

}  // namespace cli
}  // namespace sift_hull
