#include "setting_options.h"

#include <sstream>
#include <vector>

namespace sift_hull {
namespace cli {
namespace {

std::vector<std::string> commaSeparated(const std::string& text) {
  std::vector<std::string> parts;
  if (text.empty()) return parts;
  std::istringstream in(text);
  std::string part;
  while (std::getline(in, part, ',')) parts.push_back(part);
  return parts;
}

double numberOf(const SettingInfo& info, const std::string& text) {
  try {
    size_t used = 0;
    const double value = std::stod(text, &used);
    if (used == text.size()) return value;
  } catch (const std::exception&) {
  }
  throw std::invalid_argument(info.name + " must be a number, not '" + text + "'");
}

}  // namespace

std::string optionName(const std::string& setting_name) {
  std::string name = setting_name;
  // Only the leading name: a message "<name> must be ..." keeps its words.
  for (char& c : name) {
    if (c == ' ') break;
    if (c == '_') c = '-';
  }
  return name;
}

SettingValue optionValue(const ArgParser& parser, const SettingInfo& info) {
  const std::string option = optionName(info.name);
  switch (info.type) {
    case SettingType::kBool: {
      if (!parser.has(option)) return false;
      const std::string text = parser.get(option);
      if (text == "1" || text == "true") return true;  // "1": a flag given
      if (text == "0" || text == "false") return false;
      throw std::invalid_argument(info.name + " must be true or false, not '" + text + "'");
    }
    case SettingType::kInt:
    case SettingType::kSize: {
      const std::string text = parser.get(option);
      const double value = numberOf(info, text);
      if (value != static_cast<double>(static_cast<long long>(value)) ||
          text.find_first_of(".eE") != std::string::npos) {
        throw std::invalid_argument(info.name + " must be an integer, not '" + text + "'");
      }
      if (info.type == SettingType::kInt) {
        if (value < -2147483648.0 || value > 2147483647.0) {
          throw std::invalid_argument(info.name + " is out of range: " + text);
        }
        return static_cast<int>(value);
      }
      if (value < 0.0) throw std::invalid_argument(info.name + " must be >= 0, not " + text);
      return static_cast<size_t>(value);
    }
    case SettingType::kDouble:
      return numberOf(info, parser.get(option));
    case SettingType::kString:
      return parser.get(option);
    case SettingType::kStringList:
      return commaSeparated(parser.get(option));
    case SettingType::kNumberList: {
      std::vector<double> numbers;
      for (const std::string& part : commaSeparated(parser.get(option))) {
        numbers.push_back(numberOf(info, part));
      }
      return numbers;
    }
  }
  throw std::logic_error("optionValue: unknown setting type");
}

}  // namespace cli
}  // namespace sift_hull
