// libFuzzer harness: sift_hull::parseNpyMatrix (io/llff.h) with 17 columns, as readLlffPoses
// reads poses_bounds.npy, on arbitrary bytes. Any std::exception is accepted; a crash, abort,
// sanitizer report, leak or time-out is a finding.
#include <cstddef>
#include <cstdint>
#include <exception>
#include <sstream>
#include <string>

#include "sift_hull/io/llff.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  const std::string bytes(reinterpret_cast<const char*>(data), size);
  std::istringstream in(bytes);
  try {
    sift_hull::parseNpyMatrix(in, bytes.size(), "poses_bounds.npy", 17);
  } catch (const std::exception&) {
  }
  return 0;
}
