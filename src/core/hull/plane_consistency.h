#pragma once
// What lies on the support plane below the object (a floor, a table, a turntable, the object's
// shadow on them), found by the plane's homographies between the views: the "views" silhouettes'
// support cue (sift_hull/hull/view_silhouettes.h).

#include <Eigen/Core>
#include <opencv2/core.hpp>
#include <optional>
#include <vector>

#include "hull/view_prior.h"
#include "sift_hull/geometry/camera.h"

namespace sift_hull {
namespace view_prior {

/// The pixels of view `v` (working size) that lie on the plane {X : up . X = height}: each
/// pixel's 7x7 grey patch, carried into one of the `neighbours` views nearest in direction that
/// look at the plane from above by the homography the plane induces, matches there (NCC above
/// kPlaneNcc, both patches textured) better than through the plane `above` higher (what stands
/// on the plane, near its base). A textureless patch is not judged. 255 on the plane.
/// A working-size BGR image as onPlane compares it: grey, CV_32F on [0, 1].
cv::Mat planeGrey(const cv::Mat& bgr);

/// (`greys`: planeGrey of every view, made once for the set.)
cv::Mat onPlane(const std::vector<cv::Mat>& greys, const std::vector<PinholeCamera>& cameras,
                const PixelScale& scale, size_t v, const Eigen::Vector3d& up, double height,
                double above, int neighbours);

/// The height along `up` of a plane on which the views agree (a floor, a table, a turntable
/// seen around the object), swept from `low` to `high` in `step`s: the height at which the most
/// pixels of a few views outside the `objects` masks (any size; grown by 3 pixels) agree with
/// their nearest view through the plane's homography (as onPlane judges them, at half the working
/// size); nullopt when at best under kMinPlaneShare of those pixels do (no support plane seen).
/// `share` gets the share at the height found.
std::optional<double> supportHeight(const std::vector<cv::Mat>& images,
                                    const std::vector<cv::Mat>& objects,
                                    const std::vector<PinholeCamera>& cameras,
                                    const PixelScale& scale, const Eigen::Vector3d& up, double low,
                                    double high, double step, double* share = nullptr);

inline constexpr double kPlaneNcc = 0.8;
inline constexpr int kPlaneWindow = 7;
inline constexpr double kMinPlaneShare = 0.1;

}  // namespace view_prior
}  // namespace sift_hull
