// libFuzzer harness: sift_hull::readNerfTransforms (io/nerf.h) on arbitrary bytes as a
// transforms.json. Any std::exception is accepted; a crash, abort, sanitizer report, leak or
// time-out is a finding.
#include <cstddef>
#include <cstdint>
#include <exception>

#include "fuzz_input_file.h"
#include "sift_hull/io/nerf.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  static const sift_hull::fuzz::InputFile file("transforms.json");
  try {
    sift_hull::readNerfTransforms(file.write(data, size));
  } catch (const std::exception&) {
  }
  return 0;
}
