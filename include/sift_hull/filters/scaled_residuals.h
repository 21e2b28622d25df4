#pragma once
// Residuals measured against what each keypoint can promise. SIFT locates a keypoint to a
// fraction of the sampling interval of the octave it was found in, and that interval doubles
// with each octave: a keypoint of a zoomed-in view, or a coarse blob, is located less well in
// pixels than a fine corner. A tolerance fixed in pixels then drops correct matches of large
// keypoints; measured in octave intervals, one tolerance serves every scale.

#include <string>
#include <utility>
#include <vector>

#include "sift_hull/filters/two_view_models.h"

namespace sift_hull {

/// Base blur of SIFT's octaves (OpenCV's and SiftConfig::sigma_px's default), px.
inline constexpr float kSiftBaseSigmaPx = 1.6f;

/// The sampling interval of a keypoint's SIFT octave, px: its size (OpenCV's diameter,
/// 2 sigma 2^(octave + layer / layers) in image pixels) over 2 sigma, the size at the octave's
/// first layer; at least 1 (a keypoint of the first octaves, or one without a size, is located
/// to a pixel).
float octaveInterval_px(float keypoint_size_px);

/// How far a homography stretches the image about a left point: the square root of its
/// Jacobian's determinant there, |det H| / |w|^3 with w = H's last row times (x, y, 1). 1 for a
/// fundamental matrix (no scale of its own) and where undefined.
double localScale(const TwoViewModel& model, double lx, double ly);

/// The octave intervals of each pair's keypoints in the left and the right image.
struct PairScales {
  std::vector<float> left, right;
  size_t size() const { return left.size(); }
  void push(float l, float r) { left.push_back(l), right.push_back(r); }
};

/// The model's residual of one pair, each image's part divided by the pair's interval in that
/// image: for a fundamental matrix the distance to the epipolar line in each image, for a
/// homography the transfer error into each; the larger of the two. modelResidual() when both
/// intervals are 1. Infinite when undefined.
double scaledModelResidual(const TwoViewModel& model, double lx, double ly, double rx, double ry,
                           double left_interval, double right_interval);

/// Each pair's allowance by the model's local scale s (localScale at its left point): a left point
/// located to a pixel lands within s pixels on the right, so the right image's interval is
/// max(1, s) and the left one's max(1, 1 / s); 1 and 1 for a fundamental matrix.
PairScales modelScales(const TwoViewModel& model, const PointPairs& pairs);

/// One pair's intervals (left, right) in the units `unit` names (GuidedConfig::tolerance_scale):
/// "model", as modelScales() gives them; "keypoints", octaveInterval_px of each keypoint's size;
/// anything else, pixels (1, 1).
std::pair<double, double> pairIntervals(const std::string& unit, const TwoViewModel& model,
                                        double lx, double ly, float left_size_px,
                                        float right_size_px);

/// Squared scaledModelResidual of every pair (float), into `out`. Throws std::invalid_argument
/// when `scales` does not hold one entry per pair.
void squaredScaledResiduals(const TwoViewModel& model, const PointPairs& pairs,
                            const PairScales& scales, std::vector<float>* out);

}  // namespace sift_hull
