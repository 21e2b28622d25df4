// libFuzzer harness: sift_hull::readProjectionList (io/calibration.h) on arbitrary file contents.
// Any std::exception is accepted; a crash, abort, sanitizer report, leak or time-out is a finding.
#include "fuzz_input_file.h"
#include "sift_hull/io/calibration.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  sift_hull::fuzz::readAsFile("input_projections.txt", data, size,
                              [](const std::string& path) { sift_hull::readProjectionList(path); });
  return 0;
}
