#include "sift_hull/draw/match_drawing.h"

#include <algorithm>
#include <cstdio>
#include <opencv2/imgproc.hpp>
#include <string>

namespace sift_hull {
namespace {

const cv::Scalar kGreen(0, 200, 0), kRed(0, 0, 255), kWhite(255, 255, 255), kGrey(90, 90, 90);

cv::Mat colour(const cv::Mat& image) {
  cv::Mat bgr;
  if (image.channels() == 1) {
    cv::cvtColor(image, bgr, cv::COLOR_GRAY2BGR);
  } else {
    bgr = image.clone();
  }
  return bgr;
}

/// One 8-bar chart of a normalised histogram, bars scaled so that 0.5 fills the height.
cv::Mat histogramChart(const GscHistogram& histogram, const std::string& title,
                       const cv::Scalar& bar_colour) {
  constexpr int kWidth = 320, kHeight = 200, kTop = 30, kBottom = 20;
  cv::Mat chart(kHeight, kWidth, CV_8UC3, cv::Scalar(30, 30, 30));
  cv::putText(chart, title, {8, 20}, cv::FONT_HERSHEY_SIMPLEX, 0.5, kWhite, 1, cv::LINE_AA);
  const int bar_width = kWidth / kGscSectors;
  const int usable = kHeight - kTop - kBottom;
  for (int k = 0; k < kGscSectors; ++k) {
    const int height = static_cast<int>(std::min(1.0, histogram[k] / 0.5) * usable);
    const int x = k * bar_width;
    cv::rectangle(chart, {x + 4, kHeight - kBottom - height},
                  {x + bar_width - 4, kHeight - kBottom}, bar_colour, cv::FILLED);
    cv::putText(chart, std::to_string(45 * k), {x + 6, kHeight - 5}, cv::FONT_HERSHEY_PLAIN, 0.8,
                kWhite);
  }
  cv::line(chart, {0, kHeight - kBottom}, {kWidth, kHeight - kBottom}, kGrey);
  return chart;
}

cv::Mat histogramRow(const GscHistograms& histograms, const std::string& label,
                     const cv::Scalar& bar_colour) {
  char distance[64];
  std::snprintf(distance, sizeof distance, " (distance %.3f)", histograms.distance());
  cv::Mat row;
  cv::hconcat(histogramChart(histograms.left, label + ", left" + distance, bar_colour),
              histogramChart(histograms.right, label + ", right", bar_colour), row);
  return row;
}

}  // namespace

cv::Mat drawMatchDecisions(const cv::Mat& left_image, const cv::Mat& right_image,
                           const PutativeMatches& input, const FilterResult& result) {
  const cv::Mat left = colour(left_image), right = colour(right_image);
  cv::Mat canvas(std::max(left.rows, right.rows), left.cols + right.cols, CV_8UC3, cv::Scalar(0));
  left.copyTo(canvas(cv::Rect(0, 0, left.cols, left.rows)));
  right.copyTo(canvas(cv::Rect(left.cols, 0, right.cols, right.rows)));
  const cv::Point2f offset(static_cast<float>(left.cols), 0.f);
  // Removed matches first, so that kept ones stay visible on top.
  for (int pass = 0; pass < 2; ++pass) {
    for (size_t m = 0; m < input.matches.size(); ++m) {
      if ((result.keep[m] != 0) != (pass == 1)) continue;
      const cv::Point2f a = input.left(m).pt, b = input.right(m).pt + offset;
      if (!std::isfinite(a.x + a.y + b.x + b.y)) continue;
      cv::line(canvas, a, b, pass == 1 ? kGreen : kRed, 1, cv::LINE_AA);
    }
  }
  return canvas;
}

cv::Mat drawGscHistograms(const GscHistograms& kept, const GscHistograms& removed) {
  cv::Mat figure;
  cv::vconcat(histogramRow(kept, "kept match", kGreen),
              histogramRow(removed, "removed match", kRed), figure);
  return figure;
}

}  // namespace sift_hull
