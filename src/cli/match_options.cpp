#include "match_options.h"

#include <stdexcept>

#include "setting_options.h"
#include "sift_hull/filters/filter.h"

namespace sift_hull {
namespace cli {

void addFilterOptions(ArgParser* parser) { addSettingOptions(parser, settingsOf<FilterConfigs>()); }

FilterConfigs filterConfigsFromArgs(const ArgParser& parser) {
  FilterConfigs filters;
  settingsFromArgs(parser, settingsOf<FilterConfigs>(), &filters);
  validateOptions(filters);
  return filters;
}

void addMatchOptions(ArgParser* parser) {
  addSettingOptions(parser, settingsOf<SiftConfig>());
  addSettingOptions(parser, settingsOf<MatchConfig>());
  addFilterOptions(parser);
}

MatchOptions matchOptionsFromArgs(const ArgParser& parser) {
  MatchOptions options;
  settingsFromArgs(parser, settingsOf<SiftConfig>(), &options.sift);
  settingsFromArgs(parser, settingsOf<MatchConfig>(), &options.matching);
  options.filters = filterConfigsFromArgs(parser);
  validateOptions(options.sift);
  validateOptions(options.matching);
  return options;
}

}  // namespace cli
}  // namespace sift_hull
