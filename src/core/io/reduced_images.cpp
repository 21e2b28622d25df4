#include "sift_hull/io/reduced_images.h"

#include <algorithm>
#include <array>
#include <cctype>
#include <cstdint>
#include <fstream>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>
#include <stdexcept>
#include <vector>

#include "sift_hull/io/images.h"

namespace sift_hull {
namespace {

std::string lowerExtension(const std::string& path) {
  const std::string::size_type dot = path.find_last_of('.');
  const std::string::size_type slash = path.find_last_of('/');
  if (dot == std::string::npos || (slash != std::string::npos && dot < slash)) return "";
  std::string extension = path.substr(dot + 1);
  for (char& c : extension) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  return extension;
}

uint32_t bigEndian(const unsigned char* bytes, int count) {
  uint32_t value = 0;
  for (int i = 0; i < count; ++i) value = (value << 8) | bytes[i];
  return value;
}

/// A PNG's size from its IHDR chunk (the first, at byte 8); empty when the file is not a PNG.
cv::Size pngSize(std::ifstream& in) {
  std::array<unsigned char, 24> head{};
  in.seekg(0);
  if (!in.read(reinterpret_cast<char*>(head.data()), head.size())) return {};
  static const unsigned char kSignature[8] = {0x89, 'P', 'N', 'G', '\r', '\n', 0x1a, '\n'};
  if (!std::equal(kSignature, kSignature + 8, head.begin())) return {};
  if (!std::equal(head.begin() + 12, head.begin() + 16, "IHDR")) return {};
  const uint32_t width = bigEndian(head.data() + 16, 4), height = bigEndian(head.data() + 20, 4);
  if (width == 0 || height == 0 || width > INT32_MAX || height > INT32_MAX) return {};
  return cv::Size(static_cast<int>(width), static_cast<int>(height));
}

/// A JPEG's size from its first frame header (SOF0 to SOF15 but DHT, JPG and DAC); empty when the
/// file is not a JPEG, the markers end first, or an EXIF block comes first (its orientation may
/// turn the image as cv::imread decodes it: the size is then the decoded one).
cv::Size jpegSize(std::ifstream& in) {
  in.seekg(0);
  unsigned char soi[2];
  if (!in.read(reinterpret_cast<char*>(soi), 2) || soi[0] != 0xFF || soi[1] != 0xD8) return {};
  for (int markers = 0; markers < 4096; ++markers) {
    int byte = in.get();
    while (byte == 0xFF) byte = in.get();  // fill bytes
    if (byte == EOF) return {};
    const int marker = byte;
    if (marker == 0xD8 || marker == 0x01 || (marker >= 0xD0 && marker <= 0xD7)) continue;
    if (marker == 0xD9 || marker == 0xDA) return {};  // the image ends or its data starts first
    unsigned char length_bytes[2];
    if (!in.read(reinterpret_cast<char*>(length_bytes), 2)) return {};
    const uint32_t length = bigEndian(length_bytes, 2);
    if (length < 2) return {};
    const bool frame =
        marker >= 0xC0 && marker <= 0xCF && marker != 0xC4 && marker != 0xC8 && marker != 0xCC;
    if (frame) {
      unsigned char header[5];
      if (length < 7 || !in.read(reinterpret_cast<char*>(header), 5)) return {};
      const uint32_t height = bigEndian(header + 1, 2), width = bigEndian(header + 3, 2);
      if (width == 0 || height == 0) return {};  // a height given later (DNL): decode instead
      return cv::Size(static_cast<int>(width), static_cast<int>(height));
    }
    if (marker == 0xE1 && length >= 8) {  // APP1: EXIF may turn the image (cv::imread does)
      char id[6];
      if (!in.read(id, 6)) return {};
      if (std::equal(id, id + 6, "Exif\0\0")) return {};
      in.seekg(static_cast<std::streamoff>(length) - 8, std::ios::cur);
      if (!in) return {};
      continue;
    }
    in.seekg(static_cast<std::streamoff>(length) - 2, std::ios::cur);
    if (!in) return {};
  }
  return {};
}

int reducedFlag(int reduction, bool colour) {
  switch (reduction) {
    case 2:
      return colour ? cv::IMREAD_REDUCED_COLOR_2 : cv::IMREAD_REDUCED_GRAYSCALE_2;
    case 4:
      return colour ? cv::IMREAD_REDUCED_COLOR_4 : cv::IMREAD_REDUCED_GRAYSCALE_4;
    case 8:
      return colour ? cv::IMREAD_REDUCED_COLOR_8 : cv::IMREAD_REDUCED_GRAYSCALE_8;
    default:
      return colour ? cv::IMREAD_COLOR : cv::IMREAD_GRAYSCALE;
  }
}

void checkReduction(int reduction) {
  if (!isDecodableReduction(reduction)) {
    throw std::invalid_argument("a reduction of " + std::to_string(reduction) +
                                " (1, 2, 4 or 8 are decoded directly)");
  }
}

/// `image` reduced by area to reducedSize (the last row and column from what is left).
cv::Mat reducedByArea(const cv::Mat& image, int reduction) {
  const cv::Size size = reducedSize(image.size(), reduction);
  const cv::Size padded(size.width * reduction, size.height * reduction);
  cv::Mat source = image;
  if (padded != image.size()) {
    cv::copyMakeBorder(image, source, 0, padded.height - image.rows, 0, padded.width - image.cols,
                       cv::BORDER_REPLICATE);
  }
  cv::Mat reduced;
  cv::resize(source, reduced, size, 0.0, 0.0, cv::INTER_AREA);
  return reduced;
}

}  // namespace

cv::Mat maskInside(const cv::Mat& grey) {
  double low = 0.0, high = 0.0;
  cv::minMaxLoc(grey, &low, &high);
  cv::Mat mask;
  cv::compare(grey, std::max(0.0, 0.5 * high), mask, cv::CMP_GT);
  return mask;
}

bool isDecodableReduction(int reduction) {
  return reduction == 1 || reduction == 2 || reduction == 4 || reduction == 8;
}

cv::Size reducedSize(cv::Size size, int reduction) {
  return cv::Size((size.width + reduction - 1) / reduction,
                  (size.height + reduction - 1) / reduction);
}

bool hasJpegExtension(const std::string& path) {
  const std::string extension = lowerExtension(path);
  return extension == "jpg" || extension == "jpeg" || extension == "jpe" || extension == "jfif";
}

cv::Size imageFileSize(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) throw std::runtime_error(path + ": image missing or unreadable");
  cv::Size size = pngSize(in);
  if (size.empty()) {
    in.clear();
    size = jpegSize(in);
  }
  if (!size.empty()) return size;
  return readImage(path, cv::IMREAD_GRAYSCALE).size();  // with its EXIF orientation applied
}

cv::Mat reduceMask(const cv::Mat& mask, int reduction) {
  checkReduction(reduction);
  const cv::Mat inside = maskInside(mask);
  if (reduction == 1) return inside;
  return reducedByArea(inside, reduction) > 127;
}

cv::Mat readMaskReduced(const std::string& path, int reduction) {
  checkReduction(reduction);
  if (reduction > 1 && hasJpegExtension(path)) {
    return maskInside(readImage(path, reducedFlag(reduction, false)));
  }
  return reduceMask(readImage(path, cv::IMREAD_GRAYSCALE), reduction);
}

cv::Mat readImageReduced(const std::string& path, int reduction) {
  checkReduction(reduction);
  if (reduction > 1 && hasJpegExtension(path)) {
    return readImage(path, reducedFlag(reduction, true));
  }
  return reduceImage(readImage(path, cv::IMREAD_COLOR), reduction);
}

cv::Mat reduceImage(const cv::Mat& image, int reduction) {
  checkReduction(reduction);
  return reduction == 1 ? image : reducedByArea(image, reduction);
}

}  // namespace sift_hull
