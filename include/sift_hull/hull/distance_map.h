#pragma once

#include <opencv2/core.hpp>

#include "sift_hull/hull/bounding_box.h"

namespace sift_hull {

/// Signed distance transform of a silhouette in pixels: negative inside, positive outside, zero
/// on the boundary between inside and outside pixel squares (OpenCV's exact Euclidean
/// distanceTransform of the mask and of its complement). The image is padded with `padding_px`
/// pixels; a padding pixel counts as inside when it lies within the silhouette's bounds, whose
/// sides are open where the image border cuts the silhouette. So a view does not carve beyond a
/// side of its image where the object may go on, exactly as the bounding-box LP assumes.
///
/// The map covers only the inside pixels' bounding box plus `padding_px` on every side (within
/// the padded image): exact there. Look-ups elsewhere are clamped to the map, which gives a
/// lower bound of the distance (the map is convex and holds every inside pixel): safe for
/// carving, and positive, as those points are outside.
class SignedDistanceMap {
 public:
  SignedDistanceMap() = default;
  /// `mask`: CV_8UC1, non-zero inside; `bounds`: silhouetteBounds() of the mask. Throws
  /// std::invalid_argument for another type or an empty mask.
  SignedDistanceMap(const cv::Mat& mask, const SilhouetteBounds& bounds, int padding_px);
  /// A map sampled every `reduction` pixels (reducedSignedDistanceMap() makes it): element (c, r)
  /// holds the distance in image pixels at u = origin.x + c * reduction + (reduction - 1) / 2,
  /// v likewise, and differs from the full-resolution map's look-ups by at most `error_px`.
  /// Throws std::invalid_argument for a map that is not CV_32FC1 and at least 2x2, or a
  /// reduction below 1.
  SignedDistanceMap(cv::Mat distance_px, cv::Size image_size, cv::Point origin, int reduction,
                    float error_px);

  /// This map resampled for a camera with lens distortion: a map over ideal pixels (those of the
  /// undistorted pinhole, PinholeCamera) whose value at ideal pixel p is this map's at the raw
  /// pixel camera.distortPixel(p), so carving with the ideal pinhole evaluates D(distort(P X)) on
  /// the raw silhouette. The grid covers the undistorted image of this map's window plus a pixel;
  /// look-ups beyond it clamp as here. Throws std::invalid_argument when the grid would exceed four
  /// times this map's area (a distortion that blows the image up: check the coefficients).
  SignedDistanceMap undistorted(const PinholeCamera& camera) const;

  /// Bilinear look-up at pixel coordinates (pixel centres at integers), clamped to the map.
  float at(double u_px, double v_px) const;
  /// An upper bound of the map's change per pixel: 1 for a distance transform; for an undistorted
  /// map, the largest spectral norm of the distortion's Jacobian in pixels over the grid (times a
  /// 2 % margin for the spacing of its samples).
  float lipschitz() const { return lipschitz_; }
  cv::Size imageSize() const { return image_size_; }
  /// The map (CV_32FC1, continuous, at least 2x2) and the image pixel of its first element.
  const cv::Mat& map() const { return distance_px_; }
  cv::Point origin() const { return origin_; }
  /// Image pixels per map element along u and v (1: full resolution).
  int reduction() const { return reduction_; }
  /// Largest difference of a look-up from the full-resolution map's (0 at full resolution).
  float errorBound_px() const { return error_px_; }

 private:
  cv::Mat distance_px_;  ///< CV_32FC1
  cv::Size image_size_;
  cv::Point origin_;  ///< image pixel of map element (0, 0), or of its block's first pixel
  int reduction_ = 1;
  float error_px_ = 0.0f;
  float lipschitz_ = 1.0f;
};

}  // namespace sift_hull
