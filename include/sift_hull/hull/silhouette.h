#pragma once

#include <opencv2/core.hpp>
#include <string>
#include <vector>

#include "sift_hull/hull/run_length_mask.h"
#include "sift_hull/settings.h"

namespace sift_hull {

/// Silhouette extraction from images. Four methods:
/// - "auto" (the default): for a calibrated set, the "views" method's silhouettes, or the
///   "background" method's where every view's border is plain (no GrabCut needed) and they agree
///   across the views as well, to within 0.01 (silhouetteAgreement); for one image alone,
///   "background". The hull node segments its views together as they come (ViewSilhouetteSet).
/// - "views", from all the views of a calibrated set together
///   (sift_hull/hull/view_silhouettes.h): a prior from the cameras' common frusta, GrabCut with
///   the image border as background, a coarse hull tolerant of a tenth of the views, its support
///   cut, the hull's projection as the prior of a second cut. `segment_side_px` is the working
///   size. For one image alone (silhouetteFromImage) it is "background".
/// - "background", a colour model of the image border (the object rarely touches
///   it): each pixel's colour distance (CIE Lab) to the nearest of the border's colour clusters
///   (k-means, k = 8; clusters under 0.5 % of the border dropped), a threshold on that distance
///   chosen per image above the border's own spread of distances (3 times its 90th percentile, at
///   least 3 Lab units), isolated pixels and components under 5 % of the largest removed, a
///   closing by a disc of `erode_px` and the holes filled. When the clusters do not describe the
///   border (its spread above 4 Lab units: a textured background), OpenCV's GrabCut, the border
///   band as certain background, makes the silhouette (at most 640 px on the longest side,
///   upsampled), joined with the colour model's where the two agree (IoU > 0.8), then the same
///   clean-up. It needs no threshold from the user.
/// - "threshold", the Middlebury recipe: grey intensity above `threshold` (on [0, 1]), then a
///   dilation and an erosion with discs of the given radii. The command line and the nodes take
///   it when a threshold is given and no method is named.
struct SilhouetteConfig {
  std::string silhouette_method = "auto";  ///< "auto", "views", "background" or "threshold"
  double threshold = 0.19;
  int dilate_px = 10;
  int erode_px = 7;
  int segment_side_px = 400;  ///< "views": longest side of the images the cuts work on
};
/// Its settings: names, units, ranges, help (sift_hull/settings.h).
template <>
const SettingTable<SilhouetteConfig>& settingsOf<SilhouetteConfig>();

/// Throws std::invalid_argument for a threshold outside [0, 1] or a radius outside
/// [0, limits::kMaxMorphologyRadiusPx].
void validate(const SilhouetteConfig& config);

/// Mask (CV_8UC1, 255 inside, 0 outside) of the object in an 8-bit grey or BGR image, by the
/// config's method ("auto" and "views" need the other views: "background" here). `plain_border`,
/// when given, is set to whether the background method found the border plain (its colour
/// clusters describe it, so the mask is plainBackgroundSilhouette's, with no GrabCut); false for
/// the threshold method.
cv::Mat silhouetteFromImage(const cv::Mat& image, const SilhouetteConfig& config,
                            bool* plain_border = nullptr);

/// The "background" method's silhouette when the image's border is plain (its colour clusters
/// describe it, so no GrabCut is needed); an empty Mat when the border is textured.
cv::Mat plainBackgroundSilhouette(const cv::Mat& image, const SilhouetteConfig& config);

/// The colour distance of every pixel (CV_32FC1, CIE Lab units) to the nearest colour cluster of
/// the image's border band (`border_fraction` of the smaller side, at least 2 pixels wide): the
/// "background" method's evidence, before its threshold.
cv::Mat backgroundDistance(const cv::Mat& image, double border_fraction = 0.03);

/// What makes a silhouette suspect, named for the user: empty, covering more than 90 % of its
/// image, or touching all four image borders (a background taken for the object). One message per
/// suspect view, "NAME: reason; leave the view out or give its mask"; none for a good one.
std::vector<std::string> silhouetteWarnings(const std::vector<std::string>& names,
                                            const std::vector<cv::Mat>& masks);
/// silhouetteWarnings() of run-length encoded masks, decoding one at a time.
std::vector<std::string> runLengthSilhouetteWarnings(const std::vector<std::string>& names,
                                                     const std::vector<RunLengthMask>& masks);

/// The views whose reprojection IoU (one per view, e.g. ReprojectionIoU::per_view) lies far below
/// the others': more than 0.1 under the median and under 0.9. One message per such view, naming
/// it and its IoU and suggesting to leave it out.
std::vector<std::string> disagreeingViewWarnings(const std::vector<std::string>& names,
                                                 const std::vector<double>& reprojection_iou);

}  // namespace sift_hull
