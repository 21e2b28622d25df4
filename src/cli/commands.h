#pragma once

#include <nlohmann/json.hpp>
#include <string>
#include <vector>

namespace sift_hull {
namespace cli {

/// One subcommand of the sift_hull (offline) or sift_hull_ros (ROS tools) program. `run` gets the
/// arguments after the command's name and returns the exit code; it throws UsageError for a bad
/// command line and std::exception for bad input, which main reports on stderr.
struct Command {
  const char* name;
  const char* summary;
  int (*run)(const std::vector<std::string>& args);
};

/// A program: its name (for usage and error messages) and its subcommands.
struct Program {
  const char* name;
  std::vector<Command> commands;
  /// The other program and its commands, named in the error for one of them given here.
  const char* other_name = nullptr;
  std::vector<std::string> other_commands = {};
};

/// Prints a command's result: the JSON object on stdout with --json, else the human text.
void printResult(bool as_json, const nlohmann::json& result, const std::string& text);

int runDatasetInfo(const std::vector<std::string>& args);
int runScene(const std::vector<std::string>& args);
int runMatch(const std::vector<std::string>& args);
int runBenchFilters(const std::vector<std::string>& args);
int runBenchMatching(const std::vector<std::string>& args);
int runEvaluateFilters(const std::vector<std::string>& args);
int runHull(const std::vector<std::string>& args);
int runBenchHull(const std::vector<std::string>& args);

/// Parses the command line and runs the chosen command of `program`.
int runMain(const Program& program, int argc, char** argv);

}  // namespace cli
}  // namespace sift_hull
