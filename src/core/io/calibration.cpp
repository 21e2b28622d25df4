#include "sift_hull/io/calibration.h"

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

#include "sift_hull/io/view_orientation.h"
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
  orientViews(&views, path);
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
    if (c.improper()) {
      throw std::runtime_error(path + ": view '" + view.name +
                               "' has a mirrored world frame (det R = -1), which a par file cannot "
                               "hold; write a projection list");
    }
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

std::vector<PinholeCamera> camerasOf(const std::vector<CalibratedView>& views) {
  std::vector<PinholeCamera> cameras;
  for (const CalibratedView& view : views) cameras.push_back(view.camera);
  return cameras;
}

std::string parentDirectory(const std::string& path) {
  const size_t slash = path.find_last_of('/');
  if (slash == std::string::npos) return ".";
  return slash == 0 ? "/" : path.substr(0, slash);
}

}  // namespace sift_hull
