#include "filters/motion_frame.h"

namespace sift_hull {
namespace detail {

MotionFrame motionFrame(float turn_deg, float log2_scale) {
  MotionFrame frame;
  frame.turn_deg = turn_deg;
  frame.log2_scale = log2_scale;
  if (std::isfinite(log2_scale)) {
    frame.min_scale_ratio = static_cast<float>(std::exp2(log2_scale - kMaxOctavesFromMotion));
    frame.max_scale_ratio = static_cast<float>(std::exp2(log2_scale + kMaxOctavesFromMotion));
  }
  return frame;
}

}  // namespace detail
}  // namespace sift_hull
