#pragma once

#include <algorithm>
#include <cstddef>
#include <cstdint>

#include "sift_hull/hull/hull_view.h"

namespace sift_hull {
namespace detail {

/// Everything a view's batched look-ups read, as floats.
struct DistanceKernel {
  float R[9], t[3];
  float fx, skew, cx, fy, cy;  ///< K
  float k_norm;                ///< spectral norm of K's upper-left 2x2
  float slack_px;
  float behind_value;  ///< valueAt of a point not in front of the camera
  const float* map;    ///< padded distance map, row-major
  int stride;
  float offset_u, offset_v;  ///< map column / row = pixel u / v + offset
  float u_high, v_high;      ///< look-ups clamp to [0, u_high] x [0, v_high]
};

/// The highest map coordinate a look-up uses: short of the last column / row, so that the next
/// one exists.
inline float lookUpLimit(int size) { return size - 1 - 1.0f / 512; }

/// `value` clamped to [0, high]; NaN becomes 0, so a look-up never leaves the map. The AVX2 path
/// (_mm256_max_ps(value, 0), which returns its second operand for NaN) agrees.
inline float clampToMap(float value, float high) {
  return value > 0.0f ? std::min(value, high) : 0.0f;
}

/// Bilinear look-up of a row-major float map at map coordinates (u, v), clamped to
/// [0, u_high] x [0, v_high] (clampToMap). The AVX2 path (distance_kernel.cpp) does the same
/// operations.
inline float lookUp(const float* map, int stride, float u_high, float v_high, float u, float v) {
  u = clampToMap(u, u_high);
  v = clampToMap(v, v_high);
  const int u0 = static_cast<int>(u), v0 = static_cast<int>(v);
  const float fu = u - u0, fv = v - v0;
  const float* top = map + static_cast<ptrdiff_t>(v0) * stride + u0;
  const float* bottom = top + stride;
  const float upper = top[0] + fu * (top[1] - top[0]);
  const float lower = bottom[0] + fu * (bottom[1] - bottom[0]);
  return upper + fv * (lower - upper);
}

/// values[i] = max(values[i], distance look-up of point i) for one view (HullView::maxInto).
void maxDistances(const DistanceKernel& kernel, const PointBatch& points, float* values);

/// The distance at a centre and the most it changes within `radius` of it (HullView::ballBound).
void ballBound(const DistanceKernel& kernel, float x, float y, float z, float radius, float* value,
               float* reach);

/// The ball verdicts of one view for up to 32 centres (HullView::classifyBalls).
void classifyBalls(const DistanceKernel& kernel, const PointBatch& centres, float radius,
                   float* values, uint32_t* out_bits, uint32_t* in_bits);

}  // namespace detail
}  // namespace sift_hull
