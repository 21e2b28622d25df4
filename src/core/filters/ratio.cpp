#include "sift_hull/filters/ratio.h"

namespace sift_hull {

FilterResult filterRatio(const PutativeMatches& input) {
  FilterResult result = FilterResult::keepingNone(input.matches.size());
  for (size_t m = 0; m < input.matches.size(); ++m) {
    if (!input.hasFinitePositions(m)) continue;
    result.keep[m] = 1;
    result.score[m] = input.matches[m].distance;
  }
  return result;
}

}  // namespace sift_hull
