#pragma once

#include <cstdint>

#include "sift_hull/visual_hull.h"

namespace sift_hull {
namespace detail {

/// values[i] = max(values[i], distance look-up of point i) for one view (HullView::maxInto).
void maxDistances(const DistanceKernel& kernel, const PointBatch& points, float* values);

/// The ball verdicts of one view for up to 32 centres (HullView::classifyBalls).
void classifyBalls(const DistanceKernel& kernel, const PointBatch& centres, float radius,
                   float* values, uint32_t* out_bits, uint32_t* in_bits);

}  // namespace detail
}  // namespace sift_hull
