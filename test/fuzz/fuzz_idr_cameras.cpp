// libFuzzer harness: sift_hull::parseIdrCameraMatrices (io/idr.h) on arbitrary bytes as a
// cameras.npz held in memory (the same reader as readIdrCameraMatrices, over minizip's file
// functions), then idrObjectBox and idrViews with one image name per world_mat, as readIdrCameras
// reads an IDR / NeuS camera file. Any std::exception is accepted; a crash, abort, sanitizer
// report, leak or time-out is a finding.
#include <cstddef>
#include <cstdint>
#include <exception>
#include <string>
#include <vector>

#include "sift_hull/io/idr.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  const std::string bytes(reinterpret_cast<const char*>(data), size);
  try {
    const sift_hull::IdrCameras cameras = sift_hull::parseIdrCameraMatrices(bytes, "cameras.npz");
    sift_hull::idrObjectBox(cameras);
    std::vector<std::string> names;
    for (size_t i = 0; i < cameras.world_mats.size(); ++i) {
      names.push_back(std::to_string(i) + ".png");
    }
    sift_hull::idrViews(cameras, names, "cameras.npz");
  } catch (const std::exception&) {
  }
  return 0;
}
