#pragma once

#include <Eigen/Core>
#include <opencv2/core.hpp>
#include <string>

namespace sift_hull {

/// Reads a disparity image (e.g. Middlebury's PGM/PNG) and divides it by `scale` (Middlebury
/// 2003 quarter-size: 4). Returns CV_32FC1 disparities in pixels; 0 stays 0 (unknown). Throws
/// std::runtime_error when the file cannot be read.
cv::Mat readDisparity(const std::string& path, double scale);

/// Reads a 3x3 homography written as 9 whitespace-separated numbers (Oxford's H1to2p format).
/// Throws ParseError (naming the file) when it does not hold exactly 9 finite numbers.
Eigen::Matrix3d readHomography(const std::string& path);

}  // namespace sift_hull
