#include "sift_hull/settings.h"

#include <algorithm>
#include <sstream>

namespace sift_hull {
namespace {

std::string numberText(double value) {
  if (std::isinf(value)) return value > 0 ? "inf" : "-inf";
  // Whole numbers in full (1000000, not 1e+06).
  if (value == std::floor(value) && std::abs(value) < 1e15) {
    return std::to_string(static_cast<long long>(value));
  }
  std::ostringstream out;
  out << value;
  return out.str();
}

/// Throws unless `value` lies in the setting's range (and is no NaN, and finite where it must be).
void checkNumber(const SettingInfo& info, double value) {
  const bool above_min = info.min_exclusive ? value > info.min : value >= info.min;
  const bool below_max = info.max_exclusive ? value < info.max : value <= info.max;
  const bool in_range = above_min && below_max;
  const bool finite_enough = std::isfinite(value) || (info.allow_infinity && !std::isnan(value));
  if (in_range && finite_enough) return;
  std::string text =
      info.name + (info.allow_infinity ? " must be a number" : " must be a finite number");
  const std::string range = settingRangeText(info);
  const bool interval = range[0] == '[' || range[0] == '(';
  if (range != "any") text += (interval ? " in " : " ") + range;  // "any": no range to name
  throw std::invalid_argument(text + ", not " + numberText(value));
}

void checkChoice(const SettingInfo& info, const std::string& value) {
  if (info.choices.empty()) return;
  if (std::find(info.choices.begin(), info.choices.end(), value) != info.choices.end()) return;
  throw std::invalid_argument(info.name + " must be one of " + settingRangeText(info) + ", not '" +
                              value + "'");
}

}  // namespace

const char* settingTypeName(SettingType type) {
  switch (type) {
    case SettingType::kBool:
      return "boolean";
    case SettingType::kInt:
      return "integer";
    case SettingType::kSize:
      return "non-negative integer";
    case SettingType::kDouble:
      return "number";
    case SettingType::kString:
      return "string";
    case SettingType::kStringList:
      return "list of strings";
    case SettingType::kNumberList:
      return "list of numbers";
  }
  return "value";
}

void checkSetting(const SettingInfo& info, const SettingValue& value) {
  if (static_cast<size_t>(info.type) != value.index()) {
    throw std::invalid_argument(info.name + " must be a " + settingTypeName(info.type));
  }
  switch (info.type) {
    case SettingType::kBool:
      return;
    case SettingType::kInt:
      return checkNumber(info, std::get<int>(value));
    case SettingType::kSize:
      return checkNumber(info, static_cast<double>(std::get<size_t>(value)));
    case SettingType::kDouble:
      return checkNumber(info, std::get<double>(value));
    case SettingType::kString:
      return checkChoice(info, std::get<std::string>(value));
    case SettingType::kStringList:
      for (const std::string& s : std::get<std::vector<std::string>>(value)) checkChoice(info, s);
      return;
    case SettingType::kNumberList:
      for (double v : std::get<std::vector<double>>(value)) checkNumber(info, v);
      return;
  }
}

std::string settingText(const SettingValue& value) {
  struct Visitor {
    std::string operator()(bool v) const { return v ? "true" : "false"; }
    std::string operator()(int v) const { return std::to_string(v); }
    std::string operator()(size_t v) const { return std::to_string(v); }
    std::string operator()(double v) const { return numberText(v); }
    std::string operator()(const std::string& v) const { return v; }
    std::string operator()(const std::vector<std::string>& v) const {
      std::string text = "[";
      for (size_t i = 0; i < v.size(); ++i) text += (i ? ", " : "") + v[i];
      return text + "]";
    }
    std::string operator()(const std::vector<double>& v) const {
      std::string text = "[";
      for (size_t i = 0; i < v.size(); ++i) text += (i ? ", " : "") + numberText(v[i]);
      return text + "]";
    }
  };
  return std::visit(Visitor{}, value);
}

std::string settingDescription(const SettingInfo& info) {
  std::string note = info.unit;
  const std::string range = settingRangeText(info);
  if (range != "any" && range != "true, false") note += (note.empty() ? "" : "; ") + range;
  return note.empty() ? info.help : info.help + " (" + note + ")";
}

std::string settingRangeText(const SettingInfo& info) {
  if (!info.choices.empty()) {
    std::string text;
    for (size_t i = 0; i < info.choices.size(); ++i) text += (i ? ", " : "") + info.choices[i];
    return text;
  }
  if (info.type == SettingType::kBool) return "true, false";
  if (info.type == SettingType::kString || info.type == SettingType::kStringList) return "any";
  const bool has_min = std::isfinite(info.min);
  const bool has_max = std::isfinite(info.max);
  const std::string open = info.min_exclusive ? "(" : "[";
  const std::string close = info.max_exclusive ? ")" : "]";
  if (has_min && has_max) return open + numberText(info.min) + ", " + numberText(info.max) + close;
  if (has_min) return (info.min_exclusive ? "> " : ">= ") + numberText(info.min);
  if (has_max) return (info.max_exclusive ? "< " : "<= ") + numberText(info.max);
  return "any";
}

}  // namespace sift_hull
