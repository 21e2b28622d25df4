#pragma once

#include <opencv2/core.hpp>
#include <string>

namespace sift_hull {

/// Writes a CV_32FC1 image as a Portable Float Map: the header "Pf\n<width> <height>\n-1\n" (one
/// channel, little endian), then float32 rows from the bottom row of the image to the top.
/// Throws std::runtime_error naming the file on failure.
void writePfm(const std::string& path, const cv::Mat& image);

/// Reads a one-channel PFM ("Pf", either byte order) into CV_32FC1, top row first.
/// Throws ParseError naming the file on a malformed header or a short file.
cv::Mat readPfm(const std::string& path);

}  // namespace sift_hull
