#include "commands.h"

#include <cstdlib>
#include <cstring>
#include <exception>
#include <new>
#include <iostream>

#include "args.h"
#include "sift_hull/limits.h"

namespace sift_hull {
namespace cli {
namespace {

void printUsage(std::ostream& out) {
  out << "usage: sift_hull <command> [options]\n\ncommands:\n";
  for (const Command& command : commands()) {
    out << "  " << command.name << std::string(16 - std::strlen(command.name), ' ')
        << command.summary << '\n';
  }
  out << "\n'sift_hull <command> --help' describes a command.\n";
}

const Command* findCommand(const std::string& name) {
  for (const Command& command : commands()) {
    if (name == command.name) return &command;
  }
  return nullptr;
}

}  // namespace

const std::vector<Command>& commands() {
  static const std::vector<Command> all = {
      {"dataset-info", "summarise a calibrated view set (Middlebury par or projection list)",
       runDatasetInfo},
      {"scene", "render a synthetic scene with exact ground truth", runScene},
      {"match", "match SIFT features of two images and filter them (epipolar, gsc, ...)", runMatch},
      {"bench-filters", "time every match filter (the paper's Table 1 and an N sweep)",
       runBenchFilters},
      {"evaluate-filters", "precision and recall of every filter on Teddy and graf",
       runEvaluateFilters},
      {"hull", "visual hull of calibrated silhouettes: octree, OctoMap and mesh", runHull},
      {"bench-hull", "time the visual hull against dense carving on dino and temple", runBenchHull},
      {"bag", "write calibrated views as a ROS bag that drives both nodes", runBag},
      {"bench-nodes", "time the matcher and hull nodes as processes on topic streams",
       runBenchNodes},
  };
  return all;
}

void printResult(bool as_json, const nlohmann::json& result, const std::string& text) {
  if (as_json) {
    std::cout << result.dump(2) << std::endl;
  } else {
    std::cout << text << std::flush;
  }
}

int runMain(int argc, char** argv) {
  // OpenCV refuses to decode image files of more pixels than this (its own default is 2^30, 3 GiB
  // of colour), read once on the first decode; a value the user set stays.
  setenv("OPENCV_IO_MAX_IMAGE_PIXELS", std::to_string(limits::kMaxDecodedImagePixels).c_str(), 0);
  const std::vector<std::string> args(argv + 1, argv + argc);
  if (args.empty() || args[0] == "--help" || args[0] == "-h" || args[0] == "help") {
    printUsage(args.empty() ? std::cerr : std::cout);
    return args.empty() ? 2 : 0;
  }
  const Command* command = findCommand(args[0]);
  if (command == nullptr) {
    std::cerr << "sift_hull: unknown command '" << args[0] << "'\n\n";
    printUsage(std::cerr);
    return 2;
  }
  try {
    return command->run({args.begin() + 1, args.end()});
  } catch (const UsageError& e) {
    std::cerr << "sift_hull " << command->name << ": " << e.what() << "\n(see 'sift_hull "
              << command->name << " --help')\n";
    return 2;
  } catch (const std::bad_alloc&) {
    std::cerr << "sift_hull " << command->name
              << ": error: out of memory; lower --depth or use smaller images\n";
    return 1;
  } catch (const std::exception& e) {
    std::cerr << "sift_hull " << command->name << ": error: " << e.what() << '\n';
    return 1;
  }
}

}  // namespace cli
}  // namespace sift_hull
