#include "commands.h"

#include <algorithm>
#include <cstdlib>
#include <cstring>
#include <exception>
#include <iostream>
#include <new>

#include "args.h"
#include "sift_hull/limits.h"

namespace sift_hull {
namespace cli {
namespace {

void printUsage(const Program& program, std::ostream& out) {
  out << "usage: " << program.name << " <command> [options]\n\ncommands:\n";
  size_t width = 0;  // the longest name and two spaces, so that no name runs into its summary
  for (const Command& command : program.commands)
    width = std::max(width, std::strlen(command.name));
  for (const Command& command : program.commands) {
    out << "  " << command.name << std::string(width + 2 - std::strlen(command.name), ' ')
        << command.summary << '\n';
  }
  out << "\n'" << program.name << " <command> --help' describes a command.\n\n"
      << "The package's other programs:\n";
  for (const ProgramEntry& other : otherPrograms(program.name)) {
    out << "- " << other.name << ": " << other.summary << " (";
    for (size_t i = 0; i < other.commands.size(); ++i)
      out << (i == 0 ? "" : ", ") << other.commands[i];
    out << ")\n";
  }
}

const Command* findCommand(const Program& program, const std::string& name) {
  for (const Command& command : program.commands) {
    if (name == command.name) return &command;
  }
  return nullptr;
}

/// The program of the package, other than `self`, that has the command `name`; null when none.
const ProgramEntry* ownerOf(const std::vector<ProgramEntry>& others, const std::string& name) {
  for (const ProgramEntry& other : others) {
    const auto& commands = other.commands;
    if (std::find(commands.begin(), commands.end(), name) != commands.end()) return &other;
  }
  return nullptr;
}

}  // namespace

std::vector<ProgramEntry> otherPrograms(const std::string& self) {
  static const std::vector<ProgramEntry> all = {
      {"sift_hull", "the user's program", {"dataset-info", "scene", "match", "hull"}},
      {"sift_hull_bench",
       "benchmarks and evaluation, which write parts of docs/",
       {"bench-filters", "bench-matching", "evaluate-filters", "bench-hull"}},
      {"sift_hull_ros", "the tools that need ROS", {"bag", "bench-nodes", "settings"}},
  };
  std::vector<ProgramEntry> others;
  for (const ProgramEntry& entry : all) {
    if (self != entry.name) others.push_back(entry);
  }
  return others;
}

void printResult(bool as_json, const nlohmann::json& result, const std::string& text) {
  if (as_json) {
    std::cout << result.dump(2) << std::endl;
  } else {
    std::cout << text << std::flush;
  }
}

int runMain(const Program& program, int argc, char** argv) {
  // OpenCV refuses to decode image files of more pixels than this (its own default is 2^30, 3 GiB
  // of colour), read once on the first decode; a value the user set stays.
  setenv("OPENCV_IO_MAX_IMAGE_PIXELS", std::to_string(limits::kMaxDecodedImagePixels).c_str(), 0);
  setProgramName(program.name);
  const std::vector<std::string> args(argv + 1, argv + argc);
  if (args.empty() || args[0] == "--help" || args[0] == "-h" || args[0] == "help") {
    printUsage(program, args.empty() ? std::cerr : std::cout);
    return args.empty() ? 2 : 0;
  }
  const Command* command = findCommand(program, args[0]);
  const std::vector<ProgramEntry> others = otherPrograms(program.name);
  const ProgramEntry* owner = command == nullptr ? ownerOf(others, args[0]) : nullptr;
  if (owner != nullptr) {
    std::cerr << program.name << ": '" << args[0] << "' is a command of " << owner->name
              << ", not of " << program.name << ": run '" << owner->name << " " << args[0] << "'\n";
    return 2;
  }
  if (command == nullptr) {
    std::cerr << program.name << ": unknown command '" << args[0] << "'\n\n";
    printUsage(program, std::cerr);
    return 2;
  }
  try {
    return command->run({args.begin() + 1, args.end()});
  } catch (const UsageError& e) {
    std::cerr << program.name << " " << command->name << ": " << e.what() << "\n(see '"
              << program.name << " " << command->name << " --help')\n";
    return 2;
  } catch (const std::bad_alloc&) {
    std::cerr << program.name << " " << command->name
              << ": error: out of memory; lower --max-depth or use smaller images\n";
    return 1;
  } catch (const std::exception& e) {
    std::cerr << program.name << " " << command->name << ": error: " << e.what() << '\n';
    return 1;
  }
}

}  // namespace cli
}  // namespace sift_hull
