#pragma once

// The JSON writer of the settings tables (sift_hull/settings.h): one key per setting, named as
// the setting.

#include <nlohmann/json.hpp>

#include "sift_hull/settings.h"

namespace sift_hull {

/// The value as JSON (a number, boolean, string or array; an infinity as null, JSON's only way).
inline nlohmann::json settingJson(const SettingValue& value) {
  return std::visit([](const auto& v) { return nlohmann::json(v); }, value);
}

/// {"<setting name>": value, ...} for every setting of `config`.
template <typename Config>
nlohmann::json settingsJson(const SettingTable<Config>& table, const Config& config) {
  nlohmann::json json = nlohmann::json::object();
  for (const Setting<Config>& s : table.settings()) json[s.info.name] = settingJson(s.get(config));
  return json;
}

}  // namespace sift_hull
