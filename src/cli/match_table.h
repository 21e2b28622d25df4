#pragma once

#include <string>
#include <vector>

#include "match_eval.h"
#include "sift_hull/features/labelled_matches.h"
#include "sift_hull/features/matching.h"

namespace sift_hull {
namespace cli {

/// Writes one row per putative match (match --out-matches): both points (px), sizes (px), angles
/// (degrees), the descriptor distance, the ground truth when there is one ("correct", "wrong",
/// "unknown") and, per filter run, its keep flag (0 or 1) and score. `.csv` (a header row, then
/// comma-separated values; NaN scores empty) or `.json` (an array of objects, NaN as null) by the
/// file's extension. Throws UsageError for another extension, std::runtime_error when the file
/// cannot be written.
/// Throws UsageError unless the path ends in .csv or .json (checked before any work).
void checkMatchTablePath(const std::string& path);

void writeMatchTable(const std::string& path, const PutativeMatches& input,
                     const std::vector<FilterRun>& runs, const std::vector<MatchTruth>* truth);

}  // namespace cli
}  // namespace sift_hull
