// libFuzzer harness: sift_hull::readPfm (io/pfm.h) on arbitrary file contents. Any std::exception
// is accepted; a crash, abort, sanitizer report, leak or time-out is a finding.
#include "fuzz_input_file.h"
#include "sift_hull/io/pfm.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  sift_hull::fuzz::readAsFile("input.pfm", data, size,
                              [](const std::string& path) { sift_hull::readPfm(path); });
  return 0;
}
