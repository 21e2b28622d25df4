#pragma once
// Mask clean-up shared by the silhouette methods (hull/silhouette.cpp, hull/view_silhouettes.cpp).

#include <opencv2/core.hpp>

namespace sift_hull {
namespace silhouette_parts {

/// An elliptic structuring element of the given radius (2 * radius + 1 pixels across).
cv::Mat disc(int radius);

/// The components of a mask (8-connected) holding at least 5 % of the largest one's area.
cv::Mat largeComponents(const cv::Mat& mask);

/// An 8-bit grey or BGR image (sRGB) as CV_32FC3 CIE Lab (D65; L in [0, 100]): OpenCV's
/// COLOR_BGR2Lab of the image scaled to [0, 1].
cv::Mat labOf(const cv::Mat& image);

}  // namespace silhouette_parts
}  // namespace sift_hull
