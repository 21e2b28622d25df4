// libFuzzer harness: sift_hull::readHomography (io/ground_truth_files.h) on arbitrary file
// contents. Any std::exception is accepted; a crash, abort, sanitizer report, leak or time-out is a
// finding.
#include "fuzz_input_file.h"
#include "sift_hull/eval/match_evaluation.h"
#include "sift_hull/io/ground_truth_files.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  sift_hull::fuzz::readAsFile("input_H1to2p", data, size,
                              [](const std::string& path) { sift_hull::readHomography(path); });
  return 0;
}
