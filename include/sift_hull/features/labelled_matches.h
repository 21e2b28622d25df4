#pragma once

#include <cstdint>
#include <vector>

#include "sift_hull/features/matching.h"

namespace sift_hull {

/// What the ground truth says about one putative match.
enum class MatchTruth : uint8_t {
  kCorrect,
  kWrong,
  kUnknown,  ///< no ground truth there; left out of the scores and counted separately
};

/// Putative matches with the ground truth's verdict on each.
struct LabelledMatches {
  PutativeMatches putative;
  std::vector<MatchTruth> truth;
};

}  // namespace sift_hull
