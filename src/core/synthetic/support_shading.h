#pragma once

#include <Eigen/Core>
#include <opencv2/core.hpp>

#include "sift_hull/synthetic/scene_support.h"

namespace sift_hull {

/// The colour (BGR) a camera ray sees where it meets the support (`hit`, from firstSupportHit): the
/// part's albedo times the ambient share, plus the direct light unless the point is in shadow.
/// `pixel_angle_rad`, the angle a pixel spans, sets how much floor detail a pixel averages.
cv::Vec3b shadeSupport(const Shape& shape, const SceneSupport& support, const SupportHit& hit,
                       const Eigen::Vector3d& origin, const Eigen::Vector3d& direction,
                       double pixel_angle_rad, unsigned seed);

}  // namespace sift_hull
