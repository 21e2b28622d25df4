#pragma once

#include <opencv2/core.hpp>

#include "sift_hull/geometry/camera.h"
#include "sift_hull/synthetic/shape.h"

namespace sift_hull {

/// The mask renderView() gives (CV_8UC1, 255 where the ray through the pixel centre hits the
/// shape), ray-casting only what it needs: the pixels every `step` pixels, then every pixel of
/// the blocks whose surrounding samples disagree. Equal to renderView()'s mask unless a part of
/// the silhouette or a hole in it fits between samples `step` pixels apart without touching one
/// (`step` 1 casts every pixel). Rows run on OpenCV's threads. Throws std::invalid_argument for an
/// empty size or a step below 1.
cv::Mat renderMask(const Shape& shape, const PinholeCamera& camera, cv::Size size, int step = 4);

}  // namespace sift_hull
