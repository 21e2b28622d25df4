#pragma once

#include "args.h"
#include "sift_hull/filters/filter.h"

namespace sift_hull {
namespace cli {

/// Everything that decides which matches a pair gets and which a filter keeps.
struct MatchOptions {
  SiftConfig sift;
  MatchConfig matching;
  FilterConfigs filters;
};

/// SIFT, matching and filter-threshold options, their defaults those of the config structs.
void addMatchOptions(ArgParser* parser);
/// Throws UsageError for values the configs reject.
MatchOptions matchOptionsFromArgs(const ArgParser& parser);

/// The filter-threshold options alone (every FilterConfigs field), for commands that choose their
/// own SIFT and matching settings.
void addFilterOptions(ArgParser* parser);
/// Throws UsageError for values the configs reject.
FilterConfigs filterConfigsFromArgs(const ArgParser& parser);

}  // namespace cli
}  // namespace sift_hull
