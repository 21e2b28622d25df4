#include "sift_hull/io/llff.h"

#include <dirent.h>
#include <sys/stat.h>

#include <Eigen/Core>
#include <algorithm>
#include <cctype>
#include <cmath>
#include <cstring>
#include <fstream>
#include <map>
#include <sstream>
#include <stdexcept>

#include "sift_hull/limits.h"

namespace sift_hull {
namespace {

[[noreturn]] void fail(const std::string& file, const std::string& message) {
  throw ParseError(file, 0, message);
}

/// The values of numpy's header dict literal, e.g. {'descr': '<f8', 'fortran_order': False,
/// 'shape': (20, 17), }: strings stay quoted-free, tuples keep their parentheses.
std::map<std::string, std::string> parseHeaderDict(const std::string& header,
                                                   const std::string& file) {
  std::map<std::string, std::string> dict;
  size_t i = header.find('{');
  const size_t close = header.rfind('}');
  if (i == std::string::npos || close == std::string::npos || close < i) {
    fail(file, "the .npy header is not a dict");
  }
  ++i;
  const auto skipSpace = [&] {
    while (i < close && (std::isspace(static_cast<unsigned char>(header[i])) || header[i] == ',')) {
      ++i;
    }
  };
  const auto quoted = [&]() -> std::string {
    if (i >= close || (header[i] != '\'' && header[i] != '"')) {
      fail(file, "malformed .npy header: expected a quoted string");
    }
    const char quote = header[i];
    const size_t end = header.find(quote, i + 1);
    if (end == std::string::npos || end > close) fail(file, "malformed .npy header: open quote");
    std::string text = header.substr(i + 1, end - i - 1);
    i = end + 1;
    return text;
  };
  for (skipSpace(); i < close; skipSpace()) {
    const std::string key = quoted();
    while (i < close && std::isspace(static_cast<unsigned char>(header[i]))) ++i;
    if (i >= close || header[i] != ':') fail(file, "malformed .npy header: expected ':'");
    ++i;
    while (i < close && std::isspace(static_cast<unsigned char>(header[i]))) ++i;
    std::string value;
    if (i < close && (header[i] == '\'' || header[i] == '"')) {
      value = quoted();
    } else if (i < close && header[i] == '(') {
      const size_t end = header.find(')', i);
      if (end == std::string::npos || end > close) fail(file, "malformed .npy header: open '('");
      value = header.substr(i, end - i + 1);
      i = end + 1;
    } else {
      const size_t end = header.find_first_of(",}", i);
      value = header.substr(i, end - i);
      while (!value.empty() && std::isspace(static_cast<unsigned char>(value.back()))) {
        value.pop_back();
      }
      i = end;
    }
    if (dict.count(key)) fail(file, "malformed .npy header: key '" + key + "' given twice");
    dict[key] = value;
  }
  return dict;
}

/// The integers of a shape tuple such as "(20, 17)" or "(20,)".
std::vector<uint64_t> parseShape(const std::string& text, const std::string& file) {
  std::vector<uint64_t> shape;
  std::string number;
  if (text.empty() || text[0] != '(') fail(file, "the .npy shape '" + text + "' is not a tuple");
  for (size_t i = 1; i < text.size(); ++i) {
    const char c = text[i];
    if (std::isdigit(static_cast<unsigned char>(c))) {
      number.push_back(c);
      if (number.size() > 12) fail(file, "the .npy shape " + text + " is too large");
    } else if (c == ',' || c == ')') {
      if (!number.empty()) shape.push_back(std::stoull(number));
      number.clear();
    } else if (!std::isspace(static_cast<unsigned char>(c))) {
      fail(file, "malformed .npy shape " + text);
    }
  }
  return shape;
}

}  // namespace

NpyMatrix parseNpyMatrix(std::istream& in, uint64_t size_bytes, const std::string& file,
                         uint64_t cols, uint64_t rows, bool allow_float32) {
  char preamble[8];
  if (size_bytes < 10 || !in.read(preamble, 8)) fail(file, "too short for a .npy file");
  if (std::memcmp(preamble, "\x93NUMPY", 6) != 0) {
    fail(file, "not a .npy file (no \\x93NUMPY magic string)");
  }
  const int major = static_cast<unsigned char>(preamble[6]);
  const int minor = static_cast<unsigned char>(preamble[7]);
  if (major < 1 || major > 3 || minor != 0) {
    fail(file, ".npy format version " + std::to_string(major) + "." + std::to_string(minor) +
                   " is not supported (1.0, 2.0, 3.0 are)");
  }
  const int length_bytes = major == 1 ? 2 : 4;
  unsigned char raw[4] = {0, 0, 0, 0};
  if (size_bytes < 8u + length_bytes || !in.read(reinterpret_cast<char*>(raw), length_bytes)) {
    fail(file, "truncated .npy header length");
  }
  const uint64_t header_length = raw[0] | (raw[1] << 8) | (static_cast<uint64_t>(raw[2]) << 16) |
                                 (static_cast<uint64_t>(raw[3]) << 24);
  const uint64_t data_offset = 8 + length_bytes + header_length;
  if (header_length > limits::kMaxNpyHeaderBytes || data_offset > size_bytes) {
    fail(file, "the .npy header length " + std::to_string(header_length) +
                   " runs past the end of the file or the limit of 65536 bytes");
  }
  std::string header(header_length, '\0');
  if (!in.read(&header[0], static_cast<std::streamsize>(header_length))) {
    fail(file, "truncated .npy header");
  }
  const auto dict = parseHeaderDict(header, file);
  for (const char* key : {"descr", "fortran_order", "shape"}) {
    if (!dict.count(key)) fail(file, std::string("the .npy header has no '") + key + "'");
  }
  const std::string& descr = dict.at("descr");
  const bool float32 = allow_float32 && descr == "<f4";
  if (descr != "<f8" && !float32) {
    fail(file, "dtype '" + descr +
                   (allow_float32 ? "' is not supported: expected little-endian float64 or "
                                    "float32 ('<f8' or '<f4')"
                                  : "' is not supported: expected little-endian float64 "
                                    "('<f8')"));
  }
  const uint64_t item_bytes = float32 ? 4 : 8;
  const std::string& order = dict.at("fortran_order");
  if (order != "False" && order != "True") {
    fail(file, "fortran_order must be True or False, not '" + order + "'");
  }
  const std::vector<uint64_t> shape = parseShape(dict.at("shape"), file);
  if (rows > 0 && (shape.size() != 2 || shape[0] != rows || shape[1] != cols)) {
    fail(file, "array shape " + dict.at("shape") + " is not (" + std::to_string(rows) + ", " +
                   std::to_string(cols) + ")");
  }
  if (shape.size() != 2 || shape[1] != cols || shape[0] < 1) {
    fail(file, "array shape " + dict.at("shape") + " is not (N, " + std::to_string(cols) +
                   ") with N >= 1");
  }
  if (shape[0] > limits::kMaxCalibrationViews) {
    fail(file, std::to_string(shape[0]) + " rows, more than the limit of 1000000");
  }
  const uint64_t count = shape[0] * cols;
  if (size_bytes - data_offset != count * item_bytes) {
    fail(file, "shape " + dict.at("shape") + " needs " + std::to_string(count * item_bytes) +
                   " bytes of data, the file has " + std::to_string(size_bytes - data_offset));
  }
  std::vector<double> stored(count);
  if (float32) {
    std::vector<float> narrow(count);
    if (!in.read(reinterpret_cast<char*>(narrow.data()),
                 static_cast<std::streamsize>(count * item_bytes))) {
      fail(file, "truncated .npy data");
    }
    std::copy(narrow.begin(), narrow.end(), stored.begin());
  } else if (!in.read(reinterpret_cast<char*>(stored.data()),
                      static_cast<std::streamsize>(count * item_bytes))) {
    fail(file, "truncated .npy data");
  }
  NpyMatrix matrix;
  matrix.rows = shape[0];
  matrix.cols = cols;
  matrix.values.resize(count);
  const bool fortran = order == "True";
  for (uint64_t r = 0; r < matrix.rows; ++r) {
    for (uint64_t c = 0; c < cols; ++c) {
      matrix.values[r * cols + c] = fortran ? stored[c * matrix.rows + r] : stored[r * cols + c];
    }
  }
  return matrix;
}

namespace {

/// The factor from the poses' image size to the images' (1 when the latter is not given): one for
/// both sides, to a pixel's rounding of each.
double imageScale(const std::string& npy_path, const std::string& where, double width,
                  double height, int image_width_px, int image_height_px) {
  if (image_width_px <= 0 || image_height_px <= 0) return 1.0;
  const double scale = image_width_px / width;
  if (std::abs(scale * height - image_height_px) <= 1.0) return scale;
  std::ostringstream message;
  message << where << ": the images are " << image_width_px << "x" << image_height_px
          << " (width x height) but the poses' [height, width] is " << height << "x" << width;
  const double swapped_scale = image_width_px / height;
  if (height != width && std::abs(swapped_scale * width - image_height_px) <= 1.0) {
    message << ": height and width are swapped (the poses give height " << height << " and width "
            << width << "; the images are " << image_height_px << " high and " << image_width_px
            << " wide)";
  } else {
    message << ", not a downscaled copy of one factor";
  }
  fail(npy_path, message.str());
}

}  // namespace

std::vector<CalibratedView> readLlffPoses(const std::string& npy_path,
                                          const std::vector<std::string>& image_names,
                                          int image_width_px, int image_height_px) {
  std::ifstream in(npy_path, std::ios::binary);
  struct stat info;
  if (!in || ::stat(npy_path.c_str(), &info) != 0 || !S_ISREG(info.st_mode)) {
    fail(npy_path, "cannot open file");
  }
  const NpyMatrix poses = parseNpyMatrix(in, static_cast<uint64_t>(info.st_size), npy_path, 17);
  if (poses.rows != image_names.size()) {
    fail(npy_path, "holds " + std::to_string(poses.rows) + " poses but there are " +
                       std::to_string(image_names.size()) + " images");
  }
  std::vector<CalibratedView> views;
  for (uint64_t i = 0; i < poses.rows; ++i) {
    const std::string where = "row " + std::to_string(i) + " (" + image_names[i] + ")";
    for (uint64_t c = 0; c < 17; ++c) {
      if (!std::isfinite(poses.at(i, c))) fail(npy_path, where + ": a value is not finite");
    }
    Eigen::Matrix<double, 3, 5> M;
    for (int r = 0; r < 3; ++r) {
      for (int c = 0; c < 5; ++c) M(r, c) = poses.at(i, r * 5 + c);
    }
    const double height = M(0, 4), width = M(1, 4), focal = M(2, 4);
    if (!(height >= 1.0 && width >= 1.0 && height <= limits::kMaxImageSidePx &&
          width <= limits::kMaxImageSidePx && focal > 0.0)) {
      fail(npy_path, where + ": [height, width, focal] must be positive (sides at most 65536)");
    }
    // LLFF's camera axes [down, right, backwards] into OpenCV's [right, down, forwards].
    Eigen::Matrix3d R_c2w;
    R_c2w.col(0) = M.col(1);
    R_c2w.col(1) = M.col(0);
    R_c2w.col(2) = -M.col(2);
    const double scale =
        imageScale(npy_path, where, width, height, image_width_px, image_height_px);
    // The images' own centre: a downscaled copy's side is rounded to whole pixels.
    const double w = image_width_px > 0 ? image_width_px : width;
    const double h = image_height_px > 0 ? image_height_px : height;
    Eigen::Matrix3d K;
    // The image centre; LLFF's pixel (0, 0) is the top-left corner, here the top-left pixel's
    // centre.
    K << scale * focal, 0.0, w / 2.0 - 0.5, 0.0, scale * focal, h / 2.0 - 0.5, 0.0, 0.0, 1.0;
    CalibratedView view;
    view.name = image_names[i];
    view.source = npy_path + " (" + where + ")";
    view.camera_model = "LLFF";
    try {
      view.camera = PinholeCamera::fromCentre(K, R_c2w.transpose(), M.col(3));
    } catch (const std::invalid_argument& e) {
      fail(npy_path, where + ": " + e.what());
    }
    views.push_back(view);
  }
  return views;
}

std::vector<std::string> listImageFiles(const std::string& directory) {
  DIR* dir = ::opendir(directory.c_str());
  if (dir == nullptr) throw std::runtime_error(directory + ": cannot read the image directory");
  std::vector<std::string> names;
  for (const dirent* entry = ::readdir(dir); entry != nullptr; entry = ::readdir(dir)) {
    std::string name = entry->d_name;
    std::string lower = name;
    std::transform(lower.begin(), lower.end(), lower.begin(),
                   [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
    const auto endsWith = [&](const std::string& suffix) {
      return lower.size() > suffix.size() &&
             lower.compare(lower.size() - suffix.size(), suffix.size(), suffix) == 0;
    };
    if (!endsWith(".png") && !endsWith(".jpg") && !endsWith(".jpeg")) continue;
    struct stat info;
    if (::stat((directory + "/" + name).c_str(), &info) == 0 && S_ISREG(info.st_mode)) {
      names.push_back(name);
    }
  }
  ::closedir(dir);
  std::sort(names.begin(), names.end());
  return names;
}

}  // namespace sift_hull
