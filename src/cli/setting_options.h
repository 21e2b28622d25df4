#pragma once

// Command-line options derived from a settings table (sift_hull/settings.h): each setting is the
// option --<name with '-' for '_'>, its default the config's value, its help the table's help with
// unit and range. A boolean whose default is false is a flag; lists are comma-separated.

#include <cctype>
#include <string>

#include "args.h"
#include "sift_hull/settings.h"

namespace sift_hull {
namespace cli {

/// The option name of a setting: lsc_max_relative_error -> lsc-max-relative-error.
std::string optionName(const std::string& setting_name);

/// The value given (or defaulted) for `info`'s option, as its setting's type; throws UsageError
/// for a value that is not of that type.
SettingValue optionValue(const ArgParser& parser, const SettingInfo& info);

template <typename Config>
void addSettingOptions(ArgParser* parser, const SettingTable<Config>& table,
                       const Config& defaults = Config()) {
  for (const Setting<Config>& s : table.settings()) {
    const SettingValue value = s.get(defaults);
    if (s.info.type == SettingType::kBool && !std::get<bool>(value)) {
      parser->addFlag(optionName(s.info.name), settingDescription(s.info));
      continue;
    }
    std::string shown = settingText(value);
    if (s.info.type == SettingType::kStringList || s.info.type == SettingType::kNumberList) {
      shown = shown.substr(1, shown.size() - 2);  // the brackets
    }
    std::string value_name = s.info.unit.empty() ? "VALUE" : s.info.unit;
    for (char& c : value_name) c = static_cast<char>(std::toupper(static_cast<unsigned char>(c)));
    parser->addOption(optionName(s.info.name), value_name, settingDescription(s.info), shown);
  }
}

/// Sets every setting of `table` on `config` from the options; throws UsageError for a value of
/// the wrong type or out of range, naming the option.
template <typename Config>
void settingsFromArgs(const ArgParser& parser, const SettingTable<Config>& table, Config* config) {
  for (const Setting<Config>& s : table.settings()) {
    if (!parser.has(optionName(s.info.name)) && s.info.type != SettingType::kBool) continue;
    try {
      const SettingValue value = optionValue(parser, s.info);
      checkSetting(s.info, value);
      s.set(config, value);
    } catch (const std::invalid_argument& error) {
      throw UsageError("--" + optionName(error.what()));
    }
  }
}

}  // namespace cli
}  // namespace sift_hull
