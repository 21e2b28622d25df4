#include "sift_hull/io/ground_truth_files.h"

#include <Eigen/Core>
#include <cmath>
#include <cstdlib>
#include <fstream>
#include <opencv2/imgcodecs.hpp>
#include <sstream>
#include <stdexcept>
#include <vector>

#include "sift_hull/io/calibration.h"
#include "sift_hull/io/pfm.h"

namespace sift_hull {

cv::Mat readDisparity(const std::string& path, double scale) {
  if (!(scale > 0.0)) throw std::invalid_argument("readDisparity: scale must be > 0");
  const bool pfm = path.size() >= 4 && path.compare(path.size() - 4, 4, ".pfm") == 0;
  const cv::Mat raw =
      pfm ? readPfm(path) : cv::imread(path, cv::IMREAD_ANYDEPTH | cv::IMREAD_GRAYSCALE);
  if (raw.empty()) throw std::runtime_error(path + ": cannot read the disparity image");
  cv::Mat disparity;
  raw.convertTo(disparity, CV_32F, 1.0 / scale);
  return disparity;
}

Eigen::Matrix3d readHomography(const std::string& path) {
  std::ifstream in(path);
  if (!in) throw std::runtime_error(path + ": cannot open the homography file");
  std::vector<double> values;
  int line_number = 0;
  for (std::string line; std::getline(in, line);) {
    ++line_number;
    std::istringstream words(line);
    for (std::string word; words >> word;) {
      char* end = nullptr;
      const double value = std::strtod(word.c_str(), &end);
      if (end != word.c_str() + word.size() || !std::isfinite(value)) {
        throw ParseError(path, line_number, "not a number: " + word);
      }
      if (values.size() == 9) throw ParseError(path, line_number, "more than 9 numbers");
      values.push_back(value);
    }
  }
  if (values.size() != 9) {
    throw ParseError(path, 1, "expected 9 numbers, found " + std::to_string(values.size()));
  }
  return Eigen::Map<const Eigen::Matrix<double, 3, 3, Eigen::RowMajor>>(values.data());
}

}  // namespace sift_hull
