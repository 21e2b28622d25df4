#pragma once
// Images read at a reduced resolution: JPEG files decoded directly at 1/2, 1/4 or 1/8 scale
// (libjpeg's DCT scaling, OpenCV's IMREAD_REDUCED_*), other files decoded once and reduced at
// once; and image sizes read from the file's header without decoding it.

#include <opencv2/core.hpp>
#include <string>

namespace sift_hull {

/// The reductions JPEG decodes directly: 1, 2, 4 and 8.
bool isDecodableReduction(int reduction);

/// An image of `size` reduced `reduction` times: each side divided, rounded up (as libjpeg gives
/// it; the last row and column cover what is left).
cv::Size reducedSize(cv::Size size, int reduction);

/// True for a file whose name ends in .jpg, .jpeg, .jpe or .jfif (any case).
bool hasJpegExtension(const std::string& path);

/// The width and height of an image file as cv::imread gives it: from a PNG's IHDR or a JPEG's
/// frame header, else (other formats, a JPEG with EXIF data, whose orientation cv::imread applies,
/// or a header this reader does not understand) by decoding the file. Throws
/// std::runtime_error naming the path when the file is missing or unreadable.
cv::Size imageFileSize(const std::string& path);

/// A mask's inside (CV_8UC1, 255 inside, 0 outside): where a grey value exceeds half the largest
/// one. Any non-zero pixel of a 0/1 or 0/255 mask; a JPEG's ringing along the outline stays out.
cv::Mat maskInside(const cv::Mat& grey);

/// A mask file (CV_8UC1, 255 inside, 0 outside) reduced `reduction` times (1, 2, 4 or 8; 1 is
/// loadMask's full-resolution mask). A JPEG is decoded at that scale and its inside taken
/// (maskInside); another file is decoded whole, its inside taken, and reduced by area, a reduced
/// pixel inside when more than half of it is. Throws std::runtime_error naming the path when it is
/// unreadable, std::invalid_argument for a reduction JPEG cannot decode.
cv::Mat readMaskReduced(const std::string& path, int reduction);

/// A full-resolution mask's inside (maskInside) reduced by area as readMaskReduced reduces one.
cv::Mat reduceMask(const cv::Mat& mask, int reduction);

/// A photograph (8-bit BGR) reduced `reduction` times, as readMaskReduced reads masks. Throws
/// std::runtime_error naming the path when it is unreadable.
cv::Mat readImageReduced(const std::string& path, int reduction);

/// An image reduced by area `reduction` times (1, 2, 4 or 8) to reducedSize() (the last row and
/// column from what is left), as readImageReduced() reduces a file it cannot decode at scale.
cv::Mat reduceImage(const cv::Mat& image, int reduction);

}  // namespace sift_hull
