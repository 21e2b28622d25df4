#pragma once

#include "sift_hull/features/matching.h"
#include "sift_hull/filters/filter_result.h"

namespace sift_hull {

/// The paper's baseline: every putative match that passed the nearest-neighbour ratio test.
FilterResult filterRatio(const PutativeMatches& input);  ///< keeps all; score: descriptor distance

}  // namespace sift_hull
