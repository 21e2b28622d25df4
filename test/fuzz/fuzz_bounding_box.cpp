// libFuzzer harness: sift_hull::hullBoundingBox (bounding_box.h) on cameras and silhouette bounds
// decoded from the input. Any std::exception (a refused camera, HullBoxError, invalid_argument)
// is accepted; a crash, abort (GLPK's included), sanitizer report, leak or time-out is a finding,
// and so is a returned box that is not finite or has a minimum above its maximum.
//
// Input layout (little endian; missing bytes read as zero):
//   byte 0: number of views, 2 + byte % 7 (2..8)
//   per view, 137 bytes:
//     6 doubles  K: fx, skew, cx, fy, cy, K(2,2)   (K = [fx skew cx; 0 fy cy; 0 0 K(2,2)])
//     4 doubles  quaternion w, x, y, z; R is its normalised rotation matrix
//     3 doubles  t                                 (x ~ K [R | t] X)
//     4 doubles  u_min, u_max, v_min, v_max of the silhouette, pixels
//     1 byte     bit 0..3: has_u_min, has_u_max, has_v_min, has_v_max; bit 4: empty
// Every double is its 8 raw bytes, so huge, tiny, subnormal, infinite and NaN values all occur.
// test/fuzz/make_seeds.py writes seeds in this layout.
#include <Eigen/Geometry>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <exception>
#include <vector>

#include "sift_hull/geometry/camera.h"
#include "sift_hull/hull/bounding_box.h"

namespace {

class Bytes {
 public:
  Bytes(const uint8_t* data, size_t size) : data_(data), size_(size) {}

  uint8_t byte() { return offset_ < size_ ? data_[offset_++] : 0; }

  double real() {
    uint8_t raw[8] = {};
    for (uint8_t& b : raw) b = byte();
    uint64_t bits = 0;
    for (int i = 7; i >= 0; --i) bits = (bits << 8) | raw[i];
    double value;
    std::memcpy(&value, &bits, sizeof value);
    return value;
  }

 private:
  const uint8_t* data_;
  size_t size_;
  size_t offset_ = 0;
};

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  Bytes in(data, size);
  const int views = 2 + in.byte() % 7;
  std::vector<sift_hull::PinholeCamera> cameras;
  std::vector<sift_hull::SilhouetteBounds> bounds(views);
  bool cameras_valid = true;
  for (int i = 0; i < views; ++i) {
    Eigen::Matrix3d K = Eigen::Matrix3d::Zero();
    K(0, 0) = in.real();
    K(0, 1) = in.real();
    K(0, 2) = in.real();
    K(1, 1) = in.real();
    K(1, 2) = in.real();
    K(2, 2) = in.real();
    const double w = in.real(), x = in.real(), y = in.real(), z = in.real();
    const Eigen::Matrix3d R = Eigen::Quaterniond(w, x, y, z).normalized().toRotationMatrix();
    Eigen::Vector3d t;
    t.x() = in.real();
    t.y() = in.real();
    t.z() = in.real();
    sift_hull::SilhouetteBounds& b = bounds[i];
    b.u_min_px = in.real();
    b.u_max_px = in.real();
    b.v_min_px = in.real();
    b.v_max_px = in.real();
    const uint8_t flags = in.byte();
    b.has_u_min = flags & 1;
    b.has_u_max = flags & 2;
    b.has_v_min = flags & 4;
    b.has_v_max = flags & 8;
    b.empty = flags & 16;
    try {
      cameras.emplace_back(K, R, t);
    } catch (const std::exception&) {
      cameras_valid = false;  // the constructor refused K or R: an accepted outcome
    }
  }
  if (!cameras_valid) return 0;
  sift_hull::Box3d box;
  try {
    box = sift_hull::hullBoundingBox(cameras, bounds);
  } catch (const std::exception&) {
    return 0;
  }
  // A box that is returned is finite and not inverted.
  for (int axis = 0; axis < 3; ++axis) {
    if (!(std::isfinite(box.min_W(axis)) && std::isfinite(box.max_W(axis)) &&
          box.min_W(axis) <= box.max_W(axis))) {
      std::fprintf(stderr, "hullBoundingBox returned a bad box: min %g %g %g, max %g %g %g\n",
                   box.min_W.x(), box.min_W.y(), box.min_W.z(), box.max_W.x(), box.max_W.y(),
                   box.max_W.z());
      std::abort();
    }
  }
  return 0;
}
