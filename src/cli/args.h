#pragma once

#include <map>
#include <opencv2/core/types.hpp>
#include <stdexcept>
#include <string>
#include <vector>

namespace sift_hull {
namespace cli {

/// A command line the user got wrong; main prints it with the command's usage and exits 2.
class UsageError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

/// Parses "--name value", "--name=value", flags and positional arguments of one subcommand.
/// The program a usage text names (sift_hull unless runMain says otherwise).
void setProgramName(const char* name);

class ArgParser {
 public:
  ArgParser(std::string command, std::string summary);

  void addFlag(const std::string& name, const std::string& help);
  void addOption(const std::string& name, const std::string& value_name, const std::string& help,
                 const std::string& default_value = "");
  void addPositional(const std::string& name, const std::string& help);

  /// Returns false, after printing the help text on stdout, when --help is among the arguments.
  /// Throws UsageError for unknown options, missing values or missing positionals.
  bool parse(const std::vector<std::string>& args);
  std::string help() const;

  bool flag(const std::string& name) const;
  bool has(const std::string& name) const;
  /// Whether the option was given on the command line (not only defaulted).
  bool given(const std::string& name) const;
  /// Throws UsageError when the option was neither given nor has a default.
  std::string get(const std::string& name) const;
  /// Every value of an option given several times, in order; else its default, if any.
  std::vector<std::string> getAll(const std::string& name) const;
  int getInt(const std::string& name) const;
  double getDouble(const std::string& name) const;

 private:
  struct Spec {
    std::string value_name;  // empty for a flag
    std::string help;
    std::string default_value;
  };
  std::string command_, summary_;
  std::vector<std::string> order_;
  std::map<std::string, Spec> specs_;
  std::vector<std::pair<std::string, std::string>> positionals_;
  void store(const std::string& name, const std::string& value);

  std::map<std::string, std::string> values_;  ///< the last value of each option
  std::map<std::string, std::vector<std::string>> repeated_values_;
};

/// "WIDTHxHEIGHT" as a size; throws UsageError naming `option` ("--size") otherwise.
cv::Size parseSizeOption(const std::string& option, const std::string& text);

/// A number as an option's default shows it (std::ostream's shortest form: 0.04, 1e-06).
std::string numberText(double value);

/// validate(config), a bad value reported as a bad command line (UsageError).
template <typename Config>
void validateOptions(const Config& config) {
  try {
    validate(config);
  } catch (const std::invalid_argument& e) {
    throw UsageError(e.what());
  }
}

}  // namespace cli
}  // namespace sift_hull
