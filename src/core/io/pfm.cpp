#include "sift_hull/io/pfm.h"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <fstream>
#include <stdexcept>

#include "sift_hull/io/calibration.h"

namespace sift_hull {
namespace {

bool hostIsLittleEndian() {
  const uint16_t probe = 1;
  uint8_t first;
  std::memcpy(&first, &probe, 1);
  return first == 1;
}

void swapBytes(cv::Mat* image) {
  for (int row = 0; row < image->rows; ++row) {
    auto* bytes = image->ptr<uint8_t>(row);
    for (int i = 0; i < image->cols * 4; i += 4) {
      std::swap(bytes[i], bytes[i + 3]);
      std::swap(bytes[i + 1], bytes[i + 2]);
    }
  }
}

}  // namespace

void writePfm(const std::string& path, const cv::Mat& image) {
  if (image.type() != CV_32FC1) throw std::invalid_argument("writePfm needs a CV_32FC1 image");
  std::ofstream out(path, std::ios::binary);
  if (!out) throw std::runtime_error(path + ": cannot write file");
  out << "Pf\n" << image.cols << ' ' << image.rows << '\n' << "-1\n";
  cv::Mat row_data;
  for (int row = image.rows - 1; row >= 0; --row) {
    image.row(row).copyTo(row_data);
    if (!hostIsLittleEndian()) swapBytes(&row_data);
    out.write(reinterpret_cast<const char*>(row_data.data), image.cols * sizeof(float));
  }
  if (!out) throw std::runtime_error(path + ": write failed");
}

namespace {

/// Throws ParseError, before anything is allocated, when the rest of the file is shorter than
/// `floats` 4-byte values (a header cannot ask for more memory than the file holds).
void checkPfmLength(const std::string& path, std::ifstream& in, size_t floats) {
  const std::streampos data_start = in.tellg();
  in.seekg(0, std::ios::end);
  const std::streampos file_end = in.tellg();
  in.seekg(data_start);
  if (data_start < 0 || file_end < data_start ||
      static_cast<size_t>(file_end - data_start) < floats * sizeof(float)) {
    throw ParseError(path, 0,
                     "the header announces " + std::to_string(floats) + " floats (" +
                         std::to_string(floats * sizeof(float)) + " bytes) but the file holds " +
                         std::to_string(std::max<std::streamoff>(0, file_end - data_start)) +
                         " bytes after it");
  }
}

}  // namespace

cv::Mat readPfm(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) throw ParseError(path, 0, "cannot open file");
  std::string magic;
  int width = 0, height = 0;
  double scale = 0.0;
  in >> magic >> width >> height >> scale;
  if (!in || magic != "Pf") throw ParseError(path, 1, "not a one-channel PFM (expected 'Pf')");
  constexpr int kMaxSide = 1 << 15;
  if (width <= 0 || height <= 0 || width > kMaxSide || height > kMaxSide || scale == 0.0 ||
      !std::isfinite(scale)) {
    throw ParseError(path, 2, "bad PFM size or scale");
  }
  in.get();  // the single white-space character ending the header
  checkPfmLength(path, in, static_cast<size_t>(width) * static_cast<size_t>(height));
  cv::Mat image(height, width, CV_32FC1);
  for (int row = height - 1; row >= 0; --row) {
    in.read(reinterpret_cast<char*>(image.ptr<float>(row)), width * sizeof(float));
  }
  if (!in) throw ParseError(path, 0, "file ends before its " + std::to_string(height) + " rows");
  if ((scale < 0.0) != hostIsLittleEndian()) swapBytes(&image);
  return image;
}

}  // namespace sift_hull
