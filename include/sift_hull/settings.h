#pragma once

// Each config struct declares its settings once, in one table bound by member pointer (as COLMAP's
// OptionManager binds each option once): name, unit, range, help text and whether users tune it at
// run time. The ROS parameter reader, the CLI options and their --help, the dynamic_reconfigure
// mapping both ways, the JSON writer, the range checks of validate(), the node parameter files
// (config/*.yaml) and the parameter tables of docs/NODES.md all derive from these tables, so a
// setting has one name everywhere (the CLI writes '-' for '_').
//
// A struct held inside another composes its names: FilterConfigs holds LscConfig under the prefix
// "lsc", so LscConfig::max_relative_error is the setting lsc_max_relative_error.

#include <cmath>
#include <cstddef>
#include <functional>
#include <limits>
#include <stdexcept>
#include <string>
#include <variant>
#include <vector>

namespace sift_hull {

/// The value of one setting, whatever its type (the alternatives in SettingType's order).
using SettingValue = std::variant<bool, int, size_t, double, std::string, std::vector<std::string>,
                                  std::vector<double>>;

enum class SettingType { kBool, kInt, kSize, kDouble, kString, kStringList, kNumberList };

/// "boolean", "integer", "non-negative integer", "number", "string", "list of strings",
/// "list of numbers".
const char* settingTypeName(SettingType type);

/// What a table says of one setting, besides how to reach it.
struct SettingInfo {
  std::string name;  ///< composed with the prefixes of the structs that hold it
  SettingType type = SettingType::kDouble;
  std::string unit;  ///< "px", "deg", "m", "s", "voxels", ...; empty: unitless
  std::string help;  ///< one sentence, no unit (the unit is shown beside it)
  /// Numbers: the closed range of accepted values; NaN is never accepted, an infinity only where
  /// allow_infinity says so. Lists: the range of each element.
  double min = -std::numeric_limits<double>::infinity();
  double max = std::numeric_limits<double>::infinity();
  bool allow_infinity = false;
  bool min_exclusive = false;  ///< min itself is refused (> min rather than >= min)
  bool max_exclusive = false;  ///< max itself is refused
  /// Strings and lists of strings: the accepted values, when the list is not empty.
  std::vector<std::string> choices;
  bool runtime = false;  ///< tuned at run time (matcher_node's dynamic_reconfigure)

  SettingInfo& range(double lo, double hi) {
    min = lo;
    max = hi;
    return *this;
  }
  SettingInfo& atLeast(double lo) { return range(lo, max); }
  /// Values greater than lo (up to hi).
  SettingInfo& above(double lo, double hi = std::numeric_limits<double>::infinity()) {
    min_exclusive = true;
    return range(lo, hi);
  }
  /// Values strictly between lo and hi.
  SettingInfo& between(double lo, double hi) {
    max_exclusive = true;
    return above(lo, hi);
  }
  SettingInfo& infinityAllowed() {
    allow_infinity = true;
    return *this;
  }
  SettingInfo& oneOf(std::vector<std::string> values) {
    choices = std::move(values);
    return *this;
  }
  SettingInfo& tunedAtRunTime() {
    runtime = true;
    return *this;
  }
};

/// Throws std::invalid_argument ("<name> must be ...") when `value` is outside what `info` accepts.
void checkSetting(const SettingInfo& info, const SettingValue& value);

/// The value as text: numbers in their shortest form (0.04, 1e-06, inf), booleans true/false,
/// lists as [a, b].
std::string settingText(const SettingValue& value);

/// The range (and choices) of a setting in words, for --help and the docs ("[0, 1]", ">= 1",
/// "any", "background, threshold").
std::string settingRangeText(const SettingInfo& info);

/// A setting's help with its unit and range after it, as --help, config/*.yaml, cfg/Matcher.cfg
/// and the docs give it: "largest distance (px; >= 0)".
std::string settingDescription(const SettingInfo& info);

/// One setting of Config: what it is, and how to read and write it on a Config.
template <typename Config>
struct Setting {
  SettingInfo info;
  std::function<SettingValue(const Config&)> get;
  /// Sets the value, which must hold the setting's type (std::invalid_argument otherwise); a value
  /// is not range-checked here (checkSetting, validate).
  std::function<void(Config*, const SettingValue&)> set;
};

template <typename T>
constexpr SettingType settingTypeOf();
template <>
constexpr SettingType settingTypeOf<bool>() { return SettingType::kBool; }
template <>
constexpr SettingType settingTypeOf<int>() { return SettingType::kInt; }
template <>
constexpr SettingType settingTypeOf<size_t>() { return SettingType::kSize; }
template <>
constexpr SettingType settingTypeOf<double>() { return SettingType::kDouble; }
template <>
constexpr SettingType settingTypeOf<std::string>() { return SettingType::kString; }
template <>
constexpr SettingType settingTypeOf<std::vector<std::string>>() {
  return SettingType::kStringList;
}
template <>
constexpr SettingType settingTypeOf<std::vector<double>>() { return SettingType::kNumberList; }

/// The value held as T; throws std::invalid_argument naming the setting when it holds another type
/// (an int is taken where a number or a non-negative integer is wanted).
template <typename T>
T settingAs(const SettingInfo& info, const SettingValue& value) {
  if (const T* held = std::get_if<T>(&value)) return *held;
  if constexpr (std::is_same_v<T, double>) {
    if (const int* i = std::get_if<int>(&value)) return *i;
    if (const size_t* s = std::get_if<size_t>(&value)) return static_cast<double>(*s);
  }
  if constexpr (std::is_same_v<T, size_t>) {
    const int* i = std::get_if<int>(&value);
    if (i != nullptr && *i >= 0) return static_cast<size_t>(*i);
  }
  if constexpr (std::is_same_v<T, int>) {
    const size_t* s = std::get_if<size_t>(&value);
    if (s != nullptr && *s <= static_cast<size_t>(std::numeric_limits<int>::max())) {
      return static_cast<int>(*s);
    }
  }
  throw std::invalid_argument(info.name + " must be a " + settingTypeName(info.type));
}

/// The settings of one config struct, in declaration order.
template <typename Config>
class SettingTable {
 public:
  /// A setting bound to `member`; the returned info may be refined in the same statement
  /// (.range(0, 1).tunedAtRunTime()).
  template <typename T>
  SettingInfo& add(const std::string& name, T Config::*member, std::string unit,
                   std::string help) {
    Setting<Config> setting;
    setting.info.name = name;
    setting.info.type = settingTypeOf<T>();
    setting.info.unit = std::move(unit);
    setting.info.help = std::move(help);
    setting.get = [member](const Config& c) { return SettingValue(c.*member); };
    const SettingInfo info = setting.info;
    setting.set = [member, info](Config* c, const SettingValue& v) {
      c->*member = settingAs<T>(info, v);
    };
    settings_.push_back(std::move(setting));
    return settings_.back().info;
  }

  /// A setting reached through functions, for a field whose type no table takes (an optional box
  /// written as a list of numbers). `set` may throw std::invalid_argument.
  SettingInfo& addCustom(const std::string& name, SettingType type, std::string unit,
                         std::string help, std::function<SettingValue(const Config&)> get,
                         std::function<void(Config*, const SettingValue&)> set) {
    Setting<Config> setting;
    setting.info.name = name;
    setting.info.type = type;
    setting.info.unit = std::move(unit);
    setting.info.help = std::move(help);
    setting.get = std::move(get);
    setting.set = std::move(set);
    settings_.push_back(std::move(setting));
    return settings_.back().info;
  }

  /// Every setting of `inner` but those named in `except`, reached through `member`, named
  /// prefix_name (or name for an empty prefix).
  template <typename Inner>
  void nest(const std::string& prefix, Inner Config::*member, const SettingTable<Inner>& inner,
            const std::vector<std::string>& except = {}) {
    for (const Setting<Inner>& s : inner.settings()) {
      bool left_out = false;
      for (const std::string& name : except) left_out = left_out || name == s.info.name;
      if (left_out) continue;
      Setting<Config> setting;
      setting.info = s.info;
      if (!prefix.empty()) setting.info.name = prefix + "_" + s.info.name;
      auto get = s.get;
      auto set = s.set;
      setting.get = [member, get](const Config& c) { return get(c.*member); };
      setting.set = [member, set](Config* c, const SettingValue& v) { set(&(c->*member), v); };
      settings_.push_back(std::move(setting));
    }
  }

  const std::vector<Setting<Config>>& settings() const { return settings_; }

  /// The setting named `name`, or nullptr.
  const Setting<Config>* find(const std::string& name) const {
    for (const Setting<Config>& s : settings_) {
      if (s.info.name == name) return &s;
    }
    return nullptr;
  }

  /// Throws std::invalid_argument for the first setting of `config` outside its range.
  void checkRanges(const Config& config) const {
    for (const Setting<Config>& s : settings_) checkSetting(s.info, s.get(config));
  }

 private:
  std::vector<Setting<Config>> settings_;
};

/// The table of a config struct; each config header declares its specialisation.
template <typename Config>
const SettingTable<Config>& settingsOf();

/// settingsOf<Config>().checkRanges(config), the message prefixed with "<what>: ".
template <typename Config>
void checkSettings(const Config& config, const std::string& what) {
  try {
    settingsOf<Config>().checkRanges(config);
  } catch (const std::invalid_argument& error) {
    throw std::invalid_argument(what + ": " + error.what());
  }
}

}  // namespace sift_hull
