#include "args.h"

#include <algorithm>
#include <cerrno>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <iostream>
#include <sstream>

namespace sift_hull {
namespace cli {
namespace {

const char* program_name = "sift_hull";

}  // namespace

void setProgramName(const char* name) { program_name = name; }

ArgParser::ArgParser(std::string command, std::string summary)
    : command_(std::move(command)), summary_(std::move(summary)) {}

void ArgParser::addFlag(const std::string& name, const std::string& help) {
  order_.push_back(name);
  specs_[name] = {"", help, ""};
}

void ArgParser::addOption(const std::string& name, const std::string& value_name,
                          const std::string& help, const std::string& default_value) {
  order_.push_back(name);
  specs_[name] = {value_name, help, default_value};
}

void ArgParser::addPositional(const std::string& name, const std::string& help) {
  positionals_.emplace_back(name, help);
}

bool ArgParser::parse(const std::vector<std::string>& args) {
  for (const std::string& arg : args) {
    if (arg == "--help" || arg == "-h") {
      std::cout << help();
      return false;
    }
  }
  size_t next_positional = 0;
  for (size_t i = 0; i < args.size(); ++i) {
    const std::string& arg = args[i];
    if (arg.rfind("--", 0) != 0) {
      if (next_positional >= positionals_.size())
        throw UsageError("unexpected argument '" + arg + "'");
      values_[positionals_[next_positional++].first] = arg;
      continue;
    }
    const size_t equals = arg.find('=');
    const std::string name =
        arg.substr(2, equals == std::string::npos ? std::string::npos : equals - 2);
    const auto spec = specs_.find(name);
    if (spec == specs_.end()) throw UsageError("unknown option --" + name);
    std::string value;
    if (spec->second.value_name.empty()) {
      if (equals != std::string::npos) throw UsageError("--" + name + " takes no value");
      value = "1";
    } else if (equals != std::string::npos) {
      value = arg.substr(equals + 1);
    } else if (i + 1 < args.size()) {
      value = args[++i];
    } else {
      throw UsageError("--" + name + " needs a value (" + spec->second.value_name + ")");
    }
    store(name, value);
  }
  if (next_positional < positionals_.size()) {
    throw UsageError("missing argument " + positionals_[next_positional].first);
  }
  return true;
}

std::string ArgParser::help() const {
  std::ostringstream out;
  out << "usage: " << program_name << " " << command_;
  for (const auto& positional : positionals_) out << ' ' << positional.first;
  out << " [options]\n\n" << summary_ << "\n";
  for (const auto& positional : positionals_) {
    out << "\n  " << positional.first << "\n      " << positional.second;
  }
  const auto option = [&](const std::string& name) {
    const Spec& spec = specs_.at(name);
    out << "\n  --" << name << (spec.value_name.empty() ? "" : " " + spec.value_name) << "\n      "
        << spec.help;
    if (!spec.default_value.empty()) out << " (default: " << spec.default_value << ")";
  };
  for (const std::string& name : order_) option(name);
  out << "\n  --help\n      show this text\n";
  return out.str();
}

void ArgParser::store(const std::string& name, const std::string& value) {
  values_[name] = value;
  repeated_values_[name].push_back(value);
}

std::vector<std::string> ArgParser::getAll(const std::string& name) const {
  const auto given = repeated_values_.find(name);
  if (given != repeated_values_.end()) return given->second;
  if (has(name)) return {get(name)};
  return {};
}

bool ArgParser::flag(const std::string& name) const { return values_.count(name) > 0; }

bool ArgParser::has(const std::string& name) const {
  return values_.count(name) > 0 ||
         (specs_.count(name) > 0 && !specs_.at(name).default_value.empty());
}

bool ArgParser::given(const std::string& name) const { return values_.count(name) > 0; }

std::string ArgParser::get(const std::string& name) const {
  const auto value = values_.find(name);
  if (value != values_.end()) return value->second;
  const auto spec = specs_.find(name);
  if (spec != specs_.end() && !spec->second.default_value.empty())
    return spec->second.default_value;
  throw UsageError("missing required option --" + name);
}

int ArgParser::getInt(const std::string& name) const {
  const std::string text = get(name);
  errno = 0;
  char* end = nullptr;
  const long value = std::strtol(text.c_str(), &end, 10);
  if (text.empty() || *end != '\0' || errno == ERANGE || value < -2147483647L ||
      value > 2147483647L) {
    throw UsageError("--" + name + " expects an integer, got '" + text + "'");
  }
  return static_cast<int>(value);
}

double ArgParser::getDouble(const std::string& name) const {
  const std::string text = get(name);
  char* end = nullptr;
  const double value = std::strtod(text.c_str(), &end);
  if (text.empty() || *end != '\0' || !std::isfinite(value)) {
    throw UsageError("--" + name + " expects a number, got '" + text + "'");
  }
  return value;
}

cv::Size parseSizeOption(const std::string& option, const std::string& text) {
  int width = 0, height = 0;
  char tail = 0;
  if (std::sscanf(text.c_str(), "%dx%d%c", &width, &height, &tail) != 2) {
    throw UsageError(option + " expects WIDTHxHEIGHT, got '" + text + "'");
  }
  return {width, height};
}

std::string numberText(double value) {
  std::ostringstream out;
  out << value;
  return out.str();
}

}  // namespace cli
}  // namespace sift_hull
