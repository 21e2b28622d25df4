#pragma once

#include <cstddef>
#include <cstdint>
#include <vector>

namespace sift_hull {

/// What a filter decides for each putative match, in the order of PutativeMatches::matches.
/// A match with a non-finite coordinate is never kept and has a NaN score, whatever the filter.
struct FilterResult {
  std::vector<uint8_t> keep;  ///< 1 to keep the match
  std::vector<double> score;  ///< the filter's own measure; see each config for its meaning

  size_t keptCount() const;
  /// A result keeping none of `matches` matches, every score NaN: where each filter starts.
  static FilterResult keepingNone(size_t matches);
};

}  // namespace sift_hull
