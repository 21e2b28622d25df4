#include "sift_hull/dataset.h"

#include <Eigen/Dense>
#include <algorithm>
#include <cerrno>
#include <cmath>
#include <cstdlib>
#include <fstream>
#include <iomanip>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>
#include <sstream>

#include "sift_hull/limits.h"

namespace sift_hull {
namespace {

std::string location(const std::string& file, int line) {
  return line > 0 ? file + ":" + std::to_string(line) : file;
}

struct Line {
  int number;
  std::vector<std::string> fields;
};

/// Non-blank, non-comment lines of a text file, split at white space.
std::vector<Line> readFields(const std::string& path) {
  std::ifstream in(path);
  if (!in) throw ParseError(path, 0, "cannot open file");
  std::vector<Line> lines;
  std::string text;
  for (int number = 1; std::getline(in, text); ++number) {
    if (text.find('\0') != std::string::npos) {
      throw ParseError(path, number, "the line holds a NUL byte: not a text file");
    }
    std::istringstream words(text);
    Line line{number, {}};
    for (std::string word; words >> word;) line.fields.push_back(word);
    if (!line.fields.empty() && line.fields.front()[0] != '#') lines.push_back(std::move(line));
  }
  return lines;
}

/// True when the whole word is a number; an underflow to 0 or a subnormal counts as one.
bool readDouble(const std::string& word, double* value) {
  char* end = nullptr;
  *value = std::strtod(word.c_str(), &end);
  return !word.empty() && end == word.c_str() + word.size();
}

bool isNumber(const std::string& word) {
  double ignored;
  return readDouble(word, &ignored);
}

double parseNumber(const std::string& word, const std::string& path, int line) {
  double value;
  if (!readDouble(word, &value)) throw ParseError(path, line, "'" + word + "' is not a number");
  if (!std::isfinite(value)) throw ParseError(path, line, "'" + word + "' is not finite");
  return value;
}

/// Reads `count` numbers starting at field `first` into a row-major matrix.
template <int Rows, int Cols>
Eigen::Matrix<double, Rows, Cols> parseMatrix(const Line& line, size_t first,
                                              const std::string& path) {
  Eigen::Matrix<double, Rows, Cols> m;
  for (int r = 0; r < Rows; ++r) {
    for (int c = 0; c < Cols; ++c) {
      m(r, c) = parseNumber(line.fields[first + r * Cols + c], path, line.number);
    }
  }
  return m;
}

template <typename MakeCamera>
CalibratedView makeView(const std::string& name, const Line& line, const std::string& path,
                        MakeCamera make_camera) {
  try {
    return CalibratedView{name, make_camera(), location(path, line.number)};
  } catch (const std::invalid_argument& e) {
    throw ParseError(path, line.number, e.what());
  }
}

CalibratedView parseParLine(const Line& line, const std::string& path) {
  constexpr size_t kFields = 1 + 9 + 9 + 3;
  if (line.fields.size() != kFields) {
    throw ParseError(
        path, line.number,
        "expected 22 fields (name, K, R, t), found " + std::to_string(line.fields.size()));
  }
  const Eigen::Matrix3d K = parseMatrix<3, 3>(line, 1, path);
  const Eigen::Matrix3d R = parseMatrix<3, 3>(line, 10, path);
  const Eigen::Vector3d t = parseMatrix<3, 1>(line, 19, path);
  return makeView(line.fields[0], line, path, [&] { return PinholeCamera(K, R, t); });
}

CalibratedView parseProjectionLine(const Line& line, const std::string& path) {
  const size_t n = line.fields.size();
  if (n != 12 && n != 13) {
    throw ParseError(path, line.number,
                     "expected 12 numbers of a 3x4 matrix, optionally after a name; found " +
                         std::to_string(n) + " fields");
  }
  const size_t first = n - 12;
  if (first == 1 && isNumber(line.fields[0])) {
    throw ParseError(
        path, line.number,
        "expected an image name before the 12 numbers, found '" + line.fields[0] + "'");
  }
  const Matrix34d P = parseMatrix<3, 4>(line, first, path);
  const std::string name = first == 1 ? line.fields[0] : std::string();
  return makeView(name, line, path, [&] { return PinholeCamera::fromProjection(P); });
}

int parseCount(const Line& line, const std::string& path) {
  constexpr long kMaxViews = 1000000;
  const std::string& word = line.fields[0];
  errno = 0;
  char* end = nullptr;
  const long count = std::strtol(word.c_str(), &end, 10);
  if (line.fields.size() != 1 || end == word.c_str() || *end != '\0') {
    throw ParseError(path, line.number, "expected a count line with the number of views");
  }
  if (count < 1 || count > kMaxViews || errno == ERANGE) {
    throw ParseError(path, line.number,
                     "the count line must give between 1 and 1000000 views, not " + word);
  }
  return static_cast<int>(count);
}

/// cv::imread of a file, or an empty Mat when it is missing or undecodable. Existence is checked
/// first because cv::imread logs its own warning for a missing file.
cv::Mat readImageFile(const std::string& path, int flags) {
  return std::ifstream(path).good() ? cv::imread(path, flags) : cv::Mat();
}

/// A line of a par file (22 fields, a name first) where a projection list was expected.
bool looksLikeParLine(const Line& line) {
  return line.fields.size() == 22 && !isNumber(line.fields[0]);
}

bool looksLikeCountLine(const Line& line) {
  if (line.fields.size() != 1) return false;
  const std::string& word = line.fields[0];
  return word.find_first_not_of("0123456789") == std::string::npos;
}

}  // namespace

ParseError::ParseError(const std::string& file, int line, const std::string& message)
    : std::runtime_error(location(file, line) + ": " + message), file_(file), line_(line) {}

std::vector<CalibratedView> readMiddleburyPar(const std::string& path) {
  const std::vector<Line> lines = readFields(path);
  if (lines.empty()) throw ParseError(path, 0, "empty file, expected a count line");
  const int count = parseCount(lines.front(), path);
  std::vector<CalibratedView> views;
  for (size_t i = 1; i < lines.size(); ++i) views.push_back(parseParLine(lines[i], path));
  if (static_cast<int>(views.size()) != count) {
    throw ParseError(path, lines.front().number,
                     "count line says " + std::to_string(count) + " views but the file has " +
                         std::to_string(views.size()));
  }
  return views;
}

std::vector<CalibratedView> readProjectionList(const std::string& path) {
  const std::vector<Line> lines = readFields(path);
  if (lines.empty()) throw ParseError(path, 0, "empty file, expected 3x4 projection matrices");
  std::vector<CalibratedView> views;
  for (const Line& line : lines) views.push_back(parseProjectionLine(line, path));
  return views;
}

std::vector<CalibratedView> readCalibration(const std::string& path) {
  const std::vector<Line> lines = readFields(path);
  if (!lines.empty() && looksLikeCountLine(lines.front())) return readMiddleburyPar(path);
  if (!lines.empty() && looksLikeParLine(lines.front())) {
    throw ParseError(path, lines.front().number,
                     "a Middlebury par line, but the file has no count line before it");
  }
  return readProjectionList(path);
}

void writeMiddleburyPar(const std::string& path, const std::vector<CalibratedView>& views) {
  std::ofstream out(path);
  if (!out) throw std::runtime_error(path + ": cannot write file");
  out << views.size() << '\n' << std::setprecision(17);
  for (const CalibratedView& view : views) {
    const PinholeCamera& c = view.camera;
    out << view.name;
    for (int r = 0; r < 3; ++r) {
      for (int col = 0; col < 3; ++col) out << ' ' << c.K()(r, col);
    }
    for (int r = 0; r < 3; ++r) {
      for (int col = 0; col < 3; ++col) out << ' ' << c.R()(r, col);
    }
    for (int r = 0; r < 3; ++r) out << ' ' << c.t()(r);
    out << '\n';
  }
  if (!out) throw std::runtime_error(path + ": write failed");
}

std::string parentDirectory(const std::string& path) {
  const size_t slash = path.find_last_of('/');
  if (slash == std::string::npos) return ".";
  return slash == 0 ? "/" : path.substr(0, slash);
}

cv::Mat readImage(const std::string& path) {
  cv::Mat image = readImageFile(path, cv::IMREAD_COLOR);
  if (image.empty()) throw std::runtime_error(path + ": image missing or unreadable");
  return image;
}

cv::Mat loadViewImage(const std::string& directory, const CalibratedView& view) {
  const std::string named_at = view.source.empty() ? "" : " (named at " + view.source + ")";
  if (view.name.empty()) {
    throw std::runtime_error((view.source.empty() ? "a view" : view.source) +
                             ": no image name for this view; put one before its numbers");
  }
  const std::string path = directory + "/" + view.name;
  cv::Mat image = readImageFile(path, cv::IMREAD_COLOR);
  if (image.empty()) throw std::runtime_error(path + ": image missing or unreadable" + named_at);
  return image;
}

void validate(const SilhouetteConfig& config) {
  if (!(config.threshold >= 0.0 && config.threshold <= 1.0)) {
    throw std::invalid_argument("SilhouetteConfig::threshold must be in [0, 1], got " +
                                std::to_string(config.threshold));
  }
  limits::requireInRange("SilhouetteConfig::dilate_px", config.dilate_px, 0,
                         limits::kMaxMorphologyRadiusPx);
  limits::requireInRange("SilhouetteConfig::erode_px", config.erode_px, 0,
                         limits::kMaxMorphologyRadiusPx);
}

cv::Mat silhouetteFromImage(const cv::Mat& image, const SilhouetteConfig& config) {
  validate(config);
  if (image.empty() || image.depth() != CV_8U) {
    throw std::invalid_argument("silhouetteFromImage needs a non-empty 8-bit image");
  }
  cv::Mat grey = image;
  if (image.channels() == 3) cv::cvtColor(image, grey, cv::COLOR_BGR2GRAY);
  cv::Mat mask;
  cv::threshold(grey, mask, config.threshold * 255.0, 255, cv::THRESH_BINARY);
  const auto disc = [](int radius) {
    return cv::getStructuringElement(cv::MORPH_ELLIPSE, cv::Size(2 * radius + 1, 2 * radius + 1));
  };
  if (config.dilate_px > 0) cv::dilate(mask, mask, disc(config.dilate_px));
  if (config.erode_px > 0) cv::erode(mask, mask, disc(config.erode_px));
  return mask;
}

cv::Mat loadMask(const std::string& path) {
  const cv::Mat raw = readImageFile(path, cv::IMREAD_GRAYSCALE);
  if (raw.empty()) throw std::runtime_error(path + ": mask missing or unreadable");
  cv::Mat mask;
  cv::compare(raw, 0, mask, cv::CMP_GT);
  return mask;
}

std::vector<cv::Mat> loadSilhouettes(const std::vector<CalibratedView>& views,
                                     const std::string& image_directory,
                                     const std::string& mask_directory,
                                     const SilhouetteConfig& recipe) {
  std::vector<cv::Mat> silhouettes;
  for (const CalibratedView& view : views) {
    const cv::Mat image = loadViewImage(image_directory, view);
    if (!silhouettes.empty() && image.size() != silhouettes.front().size()) {
      throw std::runtime_error(image_directory + "/" + view.name + ": image size differs from " +
                               views.front().name + "'s (" + std::to_string(image.cols) + "x" +
                               std::to_string(image.rows) + ", not " +
                               std::to_string(silhouettes.front().cols) + "x" +
                               std::to_string(silhouettes.front().rows) +
                               "): one calibration set is for one image size");
    }
    if (mask_directory.empty()) {
      silhouettes.push_back(silhouetteFromImage(image, recipe));
      continue;
    }
    const std::string path = mask_directory + "/" + view.name;
    silhouettes.push_back(loadMask(path));
    if (silhouettes.back().size() != image.size()) {
      throw std::runtime_error(path + ": mask size differs from the image's");
    }
  }
  return silhouettes;
}

CommonPoint opticalAxesMeetingPoint(const std::vector<CalibratedView>& views) {
  // Minimises sum_i |(I - a_i a_i^T)(X - c_i)|^2 over X, a_i the unit axis and c_i the centre.
  Eigen::Matrix3d A = Eigen::Matrix3d::Zero();
  Eigen::Vector3d b = Eigen::Vector3d::Zero();
  for (const CalibratedView& view : views) {
    const Eigen::Vector3d axis = view.camera.opticalAxis();
    const Eigen::Matrix3d projector = Eigen::Matrix3d::Identity() - axis * axis.transpose();
    A += projector;
    b += projector * view.camera.centre();
  }
  CommonPoint result;
  const Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> eigen(A);
  result.well_defined = views.size() >= 2 && eigen.eigenvalues().minCoeff() > 1e-6 * views.size();
  if (!result.well_defined) return result;
  result.point_W = A.ldlt().solve(b);
  result.in_front_of_all = true;
  for (const CalibratedView& view : views) {
    const Eigen::Vector3d axis = view.camera.opticalAxis();
    const Eigen::Vector3d offset = result.point_W - view.camera.centre();
    const double distance = (offset - axis * axis.dot(offset)).norm();
    result.max_axis_distance_m = std::max(result.max_axis_distance_m, distance);
    result.in_front_of_all &= view.camera.depth(result.point_W) > 0.0;
  }
  return result;
}

}  // namespace sift_hull
