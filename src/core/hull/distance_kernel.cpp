// Batched distance look-ups of a view: the inner loop of carving and of the mesh's samples. An
// AVX2 path handles eight points at a time with the same operations in the same order as the
// scalar path, so both give identical results.

#include "hull/distance_kernel.h"

#include <immintrin.h>

#include <algorithm>
#include <cmath>
#include <limits>

namespace sift_hull {
namespace detail {
namespace {

/// A point in the camera frame and its bilinear distance look-up (or the value of a point behind
/// the camera).
struct Projected {
  float x, y, z, value;
};

Projected project(const DistanceKernel& k, float X, float Y, float Z) {
  Projected p;
  p.x = k.R[0] * X + k.R[1] * Y + k.R[2] * Z + k.t[0];
  p.y = k.R[3] * X + k.R[4] * Y + k.R[5] * Z + k.t[1];
  p.z = k.R[6] * X + k.R[7] * Y + k.R[8] * Z + k.t[2];
  const bool in_front = p.z > 0.0f;
  const float inverse_depth = 1.0f / (in_front ? p.z : 1.0f);
  const float x = p.x * inverse_depth, y = p.y * inverse_depth;
  const float value =
      lookUp(k.map, k.stride, k.u_high, k.v_high, k.fx * x + k.skew * y + k.cx + k.offset_u,
             k.fy * y + k.cy + k.offset_v);
  p.value = in_front ? value : k.behind_value;
  return p;
}

/// |d(K x/z)| <= ||K_2x2|| |X_C| r / (z (z - r)) for any offset of length <= r: the ball's image
/// lies in this disc around the projected centre, and the distance is 1-Lipschitz in pixels.
/// Sets bit `i` of `out_bits` / `in_bits` when all of the ball is outside / inside.
void judgeBall(const DistanceKernel& k, const Projected& p, float radius, size_t i,
               uint32_t* out_bits, uint32_t* in_bits) {
  const float clearance = p.z - radius;
  const bool ahead = clearance > 0.0f;
  const float norm = std::sqrt(p.x * p.x + p.y * p.y + p.z * p.z);
  const float projected_radius =
      k.k_norm * norm * radius / (ahead ? p.z * clearance : 1.0f) + k.slack_px;
  *out_bits |= static_cast<uint32_t>(ahead && p.value - projected_radius > 0.0f) << i;
  *in_bits |= static_cast<uint32_t>(ahead && p.value + projected_radius < 0.0f) << i;
}

/// Scalar verdicts of centres [first, count), as bits from `first` on.
void classifyBallsScalar(const DistanceKernel& k, const PointBatch& centres, size_t first,
                         float radius, float* values, uint32_t* out_bits, uint32_t* in_bits) {
  for (size_t i = first; i < centres.count; ++i) {
    const Projected p = project(k, centres.x[i], centres.y[i], centres.z[i]);
    values[i] = std::max(values[i], p.value);
    judgeBall(k, p, radius, i, out_bits, in_bits);
  }
}

struct Projected8 {
  __m256 x, y, z, value;
};

__attribute__((target("avx2"))) __m256 affine(const float* row, float t, __m256 X, __m256 Y,
                                              __m256 Z) {
  const __m256 xy = _mm256_add_ps(_mm256_mul_ps(_mm256_set1_ps(row[0]), X),
                                  _mm256_mul_ps(_mm256_set1_ps(row[1]), Y));
  return _mm256_add_ps(_mm256_add_ps(xy, _mm256_mul_ps(_mm256_set1_ps(row[2]), Z)),
                       _mm256_set1_ps(t));
}

/// clampToMap on eight values: _mm256_max_ps returns its second operand (0) for NaN.
__attribute__((target("avx2"))) __m256 clampTo(__m256 value, float high) {
  return _mm256_min_ps(_mm256_max_ps(value, _mm256_setzero_ps()), _mm256_set1_ps(high));
}

__attribute__((target("avx2"))) __m256 lerp(__m256 a, __m256 b, __m256 f) {
  return _mm256_add_ps(a, _mm256_mul_ps(f, _mm256_sub_ps(b, a)));
}

__attribute__((target("avx2"))) Projected8 project8(const DistanceKernel& k, __m256 X, __m256 Y,
                                                    __m256 Z) {
  Projected8 p;
  p.x = affine(k.R, k.t[0], X, Y, Z);
  p.y = affine(k.R + 3, k.t[1], X, Y, Z);
  p.z = affine(k.R + 6, k.t[2], X, Y, Z);
  const __m256 one = _mm256_set1_ps(1.0f);
  const __m256 in_front = _mm256_cmp_ps(p.z, _mm256_setzero_ps(), _CMP_GT_OQ);
  const __m256 inverse_depth = _mm256_div_ps(one, _mm256_blendv_ps(one, p.z, in_front));
  const __m256 x = _mm256_mul_ps(p.x, inverse_depth), y = _mm256_mul_ps(p.y, inverse_depth);
  const __m256 u_raw =
      _mm256_add_ps(_mm256_add_ps(_mm256_add_ps(_mm256_mul_ps(_mm256_set1_ps(k.fx), x),
                                                _mm256_mul_ps(_mm256_set1_ps(k.skew), y)),
                                  _mm256_set1_ps(k.cx)),
                    _mm256_set1_ps(k.offset_u));
  const __m256 v_raw =
      _mm256_add_ps(_mm256_add_ps(_mm256_mul_ps(_mm256_set1_ps(k.fy), y), _mm256_set1_ps(k.cy)),
                    _mm256_set1_ps(k.offset_v));
  const __m256 u = clampTo(u_raw, k.u_high), v = clampTo(v_raw, k.v_high);
  const __m256i u0 = _mm256_cvttps_epi32(u), v0 = _mm256_cvttps_epi32(v);
  const __m256 fu = _mm256_sub_ps(u, _mm256_cvtepi32_ps(u0));
  const __m256 fv = _mm256_sub_ps(v, _mm256_cvtepi32_ps(v0));
  const __m256i top = _mm256_add_epi32(_mm256_mullo_epi32(v0, _mm256_set1_epi32(k.stride)), u0);
  const __m256i bottom = _mm256_add_epi32(top, _mm256_set1_epi32(k.stride));
  const __m256i next = _mm256_set1_epi32(1);
  const __m256 upper = lerp(_mm256_i32gather_ps(k.map, top, 4),
                            _mm256_i32gather_ps(k.map, _mm256_add_epi32(top, next), 4), fu);
  const __m256 lower = lerp(_mm256_i32gather_ps(k.map, bottom, 4),
                            _mm256_i32gather_ps(k.map, _mm256_add_epi32(bottom, next), 4), fu);
  p.value = _mm256_blendv_ps(_mm256_set1_ps(k.behind_value), lerp(upper, lower, fv), in_front);
  return p;
}

__attribute__((target("avx2"))) void maxDistancesAvx2(const DistanceKernel& k,
                                                      const PointBatch& points, float* values) {
  size_t i = 0;
  for (; i + 8 <= points.count; i += 8) {
    const Projected8 p = project8(k, _mm256_loadu_ps(points.x + i), _mm256_loadu_ps(points.y + i),
                                  _mm256_loadu_ps(points.z + i));
    _mm256_storeu_ps(values + i, _mm256_max_ps(_mm256_loadu_ps(values + i), p.value));
  }
  for (; i < points.count; ++i) {
    values[i] = std::max(values[i], project(k, points.x[i], points.y[i], points.z[i]).value);
  }
}

__attribute__((target("avx2"))) void classifyBallsAvx2(const DistanceKernel& k,
                                                       const PointBatch& centres, float radius,
                                                       float* values, uint32_t* out_bits,
                                                       uint32_t* in_bits) {
  size_t i = 0;
  const __m256 r = _mm256_set1_ps(radius), zero = _mm256_setzero_ps();
  for (; i + 8 <= centres.count; i += 8) {
    const Projected8 p = project8(k, _mm256_loadu_ps(centres.x + i), _mm256_loadu_ps(centres.y + i),
                                  _mm256_loadu_ps(centres.z + i));
    _mm256_storeu_ps(values + i, _mm256_max_ps(_mm256_loadu_ps(values + i), p.value));
    const __m256 clearance = _mm256_sub_ps(p.z, r);
    const __m256 ahead = _mm256_cmp_ps(clearance, zero, _CMP_GT_OQ);
    const __m256 norm = _mm256_sqrt_ps(_mm256_add_ps(
        _mm256_add_ps(_mm256_mul_ps(p.x, p.x), _mm256_mul_ps(p.y, p.y)), _mm256_mul_ps(p.z, p.z)));
    const __m256 denominator =
        _mm256_blendv_ps(_mm256_set1_ps(1.0f), _mm256_mul_ps(p.z, clearance), ahead);
    const __m256 projected_radius = _mm256_add_ps(
        _mm256_div_ps(_mm256_mul_ps(_mm256_mul_ps(_mm256_set1_ps(k.k_norm), norm), r), denominator),
        _mm256_set1_ps(k.slack_px));
    *out_bits |=
        static_cast<uint32_t>(_mm256_movemask_ps(_mm256_and_ps(
            ahead, _mm256_cmp_ps(_mm256_sub_ps(p.value, projected_radius), zero, _CMP_GT_OQ))))
        << i;
    *in_bits |=
        static_cast<uint32_t>(_mm256_movemask_ps(_mm256_and_ps(
            ahead, _mm256_cmp_ps(_mm256_add_ps(p.value, projected_radius), zero, _CMP_LT_OQ))))
        << i;
  }
  classifyBallsScalar(k, centres, i, radius, values, out_bits, in_bits);
}

bool hasAvx2() {
  static const bool has = __builtin_cpu_supports("avx2");
  return has;
}

}  // namespace

void maxDistances(const DistanceKernel& kernel, const PointBatch& points, float* values) {
  if (hasAvx2()) return maxDistancesAvx2(kernel, points, values);
  for (size_t i = 0; i < points.count; ++i) {
    values[i] = std::max(values[i], project(kernel, points.x[i], points.y[i], points.z[i]).value);
  }
}

void ballBound(const DistanceKernel& kernel, float x, float y, float z, float radius, float* value,
               float* reach) {
  const Projected p = project(kernel, x, y, z);
  *value = p.value;
  const float clearance = p.z - radius;
  if (!(clearance > 0.0f)) {
    *reach = std::numeric_limits<float>::infinity();
    return;
  }
  const float norm = std::sqrt(p.x * p.x + p.y * p.y + p.z * p.z);
  *reach = kernel.k_norm * norm * radius / (p.z * clearance) + kernel.slack_px;
}

void classifyBalls(const DistanceKernel& kernel, const PointBatch& centres, float radius,
                   float* values, uint32_t* out_bits, uint32_t* in_bits) {
  *out_bits = 0;
  *in_bits = 0;
  if (hasAvx2()) return classifyBallsAvx2(kernel, centres, radius, values, out_bits, in_bits);
  classifyBallsScalar(kernel, centres, 0, radius, values, out_bits, in_bits);
}

}  // namespace detail
}  // namespace sift_hull
