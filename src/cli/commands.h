#pragma once

#include <nlohmann/json.hpp>
#include <string>
#include <vector>

namespace sift_hull {
namespace cli {

/// One subcommand of the sift_hull (offline), sift_hull_bench (benchmarks and evaluation) or
/// sift_hull_ros (ROS tools) program. `run` gets the arguments after the command's name and
/// returns the exit code; it throws UsageError for a bad command line and std::exception for bad
/// input, which main reports on stderr.
struct Command {
  const char* name;
  const char* summary;
  int (*run)(const std::vector<std::string>& args);
};

/// A program: its name (for usage and error messages) and its subcommands.
struct Program {
  const char* name;
  std::vector<Command> commands;
};

/// A program of the package as the others name it: in their usage text, and in their error for
/// one of its commands.
struct ProgramEntry {
  const char* name;
  const char* summary;
  std::vector<std::string> commands;
};

/// The package's programs other than `self`, from one list of all three: sift_hull (the user's
/// commands), sift_hull_bench (benchmarks and evaluation) and sift_hull_ros (the tools that need
/// ROS).
std::vector<ProgramEntry> otherPrograms(const std::string& self);

/// Prints a command's result: the JSON object on stdout with --json, else the human text.
void printResult(bool as_json, const nlohmann::json& result, const std::string& text);

int runDatasetInfo(const std::vector<std::string>& args);
int runScene(const std::vector<std::string>& args);
int runMatch(const std::vector<std::string>& args);
int runHull(const std::vector<std::string>& args);

/// Parses the command line and runs the chosen command of `program`.
int runMain(const Program& program, int argc, char** argv);

}  // namespace cli
}  // namespace sift_hull
