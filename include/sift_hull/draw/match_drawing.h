#pragma once

#include <opencv2/core.hpp>

#include "sift_hull/filters/filter.h"

namespace sift_hull {

/// Both images side by side (BGR), each match a line: kept green, removed red.
cv::Mat drawMatchDecisions(const cv::Mat& left_image, const cv::Mat& right_image,
                           const PutativeMatches& input, const FilterResult& result);

/// Bar charts of the left and right GSC histograms of a kept and of a removed match, one row
/// each, with their distances.
cv::Mat drawGscHistograms(const GscHistograms& kept, const GscHistograms& removed);

}  // namespace sift_hull
