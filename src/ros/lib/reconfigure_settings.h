#pragma once

// The dynamic_reconfigure mapping of a settings table (sift_hull/settings.h), both ways, by name:
// the settings marked tunedAtRunTime() are the reconfigure fields of the same names (cfg/*.cfg,
// generated from the table).

#include <dynamic_reconfigure/Config.h>

#include <stdexcept>
#include <string>

#include "sift_hull/settings.h"

namespace sift_hull {
namespace ros_conversions {

/// The settings of `config` tuned at run time, as a reconfigure message. Throws
/// std::invalid_argument for a run-time setting of a type dynamic_reconfigure has no field for.
template <typename Config>
dynamic_reconfigure::Config reconfigureMessage(const SettingTable<Config>& table,
                                               const Config& config) {
  dynamic_reconfigure::Config message;
  for (const Setting<Config>& s : table.settings()) {
    if (!s.info.runtime) continue;
    const SettingValue value = s.get(config);
    if (const bool* b = std::get_if<bool>(&value)) {
      dynamic_reconfigure::BoolParameter p;
      p.name = s.info.name;
      p.value = *b;
      message.bools.push_back(p);
    } else if (const double* d = std::get_if<double>(&value)) {
      dynamic_reconfigure::DoubleParameter p;
      p.name = s.info.name;
      p.value = *d;
      message.doubles.push_back(p);
    } else if (const int* i = std::get_if<int>(&value)) {
      dynamic_reconfigure::IntParameter p;
      p.name = s.info.name;
      p.value = *i;
      message.ints.push_back(p);
    } else if (const std::string* text = std::get_if<std::string>(&value)) {
      dynamic_reconfigure::StrParameter p;
      p.name = s.info.name;
      p.value = *text;
      message.strs.push_back(p);
    } else {
      throw std::invalid_argument(s.info.name + ": no reconfigure field takes a " +
                                  settingTypeName(s.info.type));
    }
  }
  return message;
}

/// Sets each field of `message` on `config`, checked against its setting's range. Throws
/// std::invalid_argument for a field that is no run-time setting or a value out of range (the
/// config is then partly set: apply to a copy).
template <typename Config>
void applyReconfigure(const SettingTable<Config>& table, const dynamic_reconfigure::Config& message,
                      Config* config) {
  const auto apply = [&](const std::string& name, const SettingValue& value) {
    const Setting<Config>* setting = table.find(name);
    if (setting == nullptr || !setting->info.runtime) {
      throw std::invalid_argument(name + " is not a setting tuned at run time");
    }
    const SettingValue typed = [&]() -> SettingValue {
      switch (setting->info.type) {
        case SettingType::kInt:
          return settingAs<int>(setting->info, value);
        case SettingType::kSize:
          return settingAs<size_t>(setting->info, value);
        case SettingType::kDouble:
          return settingAs<double>(setting->info, value);
        default:
          return value;
      }
    }();
    checkSetting(setting->info, typed);
    setting->set(config, typed);
  };
  for (const auto& p : message.bools) apply(p.name, static_cast<bool>(p.value));
  for (const auto& p : message.ints) apply(p.name, static_cast<int>(p.value));
  for (const auto& p : message.doubles) apply(p.name, static_cast<double>(p.value));
  for (const auto& p : message.strs) apply(p.name, std::string(p.value));
}

}  // namespace ros_conversions
}  // namespace sift_hull
