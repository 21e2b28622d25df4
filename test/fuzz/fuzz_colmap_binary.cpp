// libFuzzer harness: sift_hull::parseColmapCamerasBinary and parseColmapImagesBinary
// (io/colmap.h) on arbitrary bytes, the first byte choosing the file: even for cameras.bin, odd for
// images.bin (against one PINHOLE camera of id 1). Any std::exception is accepted; a crash, abort,
// sanitizer report, leak or time-out is a finding.
#include <Eigen/Core>
#include <cstddef>
#include <cstdint>
#include <exception>
#include <sstream>
#include <string>

#include "sift_hull/io/colmap.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  if (size == 0) return 0;
  const std::string bytes(reinterpret_cast<const char*>(data) + 1, size - 1);
  std::istringstream in(bytes);
  try {
    if (data[0] % 2 == 0) {
      sift_hull::parseColmapCamerasBinary(in, bytes.size(), "cameras.bin");
    } else {
      sift_hull::ColmapCamera camera;
      camera.model = "PINHOLE";
      camera.K << 500, 0, 320, 0, 500, 240, 0, 0, 1;
      sift_hull::parseColmapImagesBinary(in, bytes.size(), "images.bin", {{1u, camera}});
    }
  } catch (const std::exception&) {
  }
  return 0;
}
