#pragma once

#include "sift_hull/geometry/camera.h"
#include "sift_hull/hull/bounding_box.h"
#include "sift_hull/hull/distance_map.h"
#include "sift_hull/hull/hull_config.h"
#include "sift_hull/hull/run_length_mask.h"

namespace sift_hull {

/// The largest reduction distanceReduction() chooses by itself.
constexpr int kMaxAutomaticDistanceReduction = 8;
/// The largest HullConfig::distance_reduction accepted.
constexpr int kMaxDistanceReduction = 15;

/// How many image pixels per side one element of a view's distance map may cover:
/// `config.distance_reduction` when it is positive; when 0, the largest integer s (1 to
/// kMaxAutomaticDistanceReduction) that does not exceed the edge in pixels of a finest voxel
/// (HullCube::around(box, max_depth).resolution_m) seen at the farthest depth of the box's
/// corners with the smaller focal length, so that a finest voxel still covers about one map
/// element. 1 when a corner of the box is not in front of the camera, and for images under
/// kMinReducedImagePixels, whose full-resolution transforms cost less than the exact band.
int distanceReduction(const PinholeCamera& camera, cv::Size image_size, const Box3d& box,
                      const HullConfig& config);

/// Images below this many pixels keep full-resolution maps when the reduction is automatic
/// (measured: a 640x480 view's reduced map at s = 2 took longer than its full transform).
constexpr int kMinReducedImagePixels = 2000000;

/// The a-priori error bound of a map of reducedSignedDistanceMap(), in pixels: `reduction` (0
/// for 1), the bilinear interpolation between samples `reduction` apart of a field whose slope is
/// at most sqrt(2) px per px (the full-resolution map's bilinear cells). A map states a bound e <=
/// this (SignedDistanceMap::errorBound_px()) such that, wherever its look-up r is not 0,
/// sign(r) (r - f) <= e for the full-resolution look-up f: r never exceeds f's magnitude by more
/// than e, nor takes the wrong sign by more than e. So adding e to the slack keeps the ball
/// verdicts conservative. Near the contour e is measured (the excess at every pixel centre and,
/// for an even reduction, every half-pixel point around the exact band: where the pieces of both
/// bilinear interpolants meet, so the excess is largest at one of them); farther away the
/// samples are lowered by `reduction` below a lower bound of the full-resolution magnitude.
float reducedDistanceErrorBound_px(int reduction);

/// SignedDistanceMap(mask.decode(), bounds, padding_px) sampled every `reduction` pixels, computed
/// without a full-resolution transform: a block of reduction x reduction pixels per element,
/// its coverage counted from the mask; blocks whose 3x3 neighbourhood holds both inside and
/// outside pixels carry the contour, and a transform of that block grid gives every sample's
/// distance to the contour up to half a block diagonal (kept as a lower bound with the sign of the
/// block). Samples within kExactBandBlocks blocks of the contour get the full-resolution map's
/// exact value from transforms of the mask in tiles around the contour. The values are image
/// pixels; errorBound_px() is the bound described at reducedDistanceErrorBound_px(). `reduction` 1,
/// or an empty silhouette, gives the full-resolution map. Throws std::invalid_argument for an empty
/// mask or a reduction outside [1, kMaxDistanceReduction].
SignedDistanceMap reducedSignedDistanceMap(const RunLengthMask& mask,
                                           const SilhouetteBounds& bounds, int padding_px,
                                           int reduction);

/// Blocks around the contour blocks whose samples are exact (reducedSignedDistanceMap()).
constexpr int kExactBandBlocks = 6;

}  // namespace sift_hull
