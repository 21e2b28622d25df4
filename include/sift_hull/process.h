#pragma once
// Starting another program (COLMAP's, the package's own in benchmarks and harnesses) with its
// output in a file.

#include <sys/types.h>

#include <string>
#include <vector>

namespace sift_hull {

/// Where a started program's output goes.
enum class ProgramOutput {
  kStdoutToFile,        ///< stdout written to the file (made anew), stderr left as it is
  kBothAppendedToFile,  ///< stdout and stderr appended to the file
};

/// Starts command[0] (looked up on PATH) with the rest of `command` as its arguments and its
/// output in `output_path` as `output` says; its pid, or -1 when it cannot be started (missing,
/// not executable, an empty command).
pid_t startProgram(const std::vector<std::string>& command, const std::string& output_path,
                   ProgramOutput output);

}  // namespace sift_hull
