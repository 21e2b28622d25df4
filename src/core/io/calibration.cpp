#include "sift_hull/io/calibration.h"

#include <sys/stat.h>

#include <Eigen/Dense>
#include <algorithm>
#include <cctype>
#include <cerrno>
#include <cmath>
#include <cstdlib>
#include <fstream>
#include <iomanip>
#include <map>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>
#include <sstream>

#include "sift_hull/io/colmap.h"
#include "sift_hull/io/idr.h"
#include "sift_hull/io/llff.h"
#include "sift_hull/io/nerf.h"
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

/// Non-blank, non-comment lines of a text file, split at white space and commas; a UTF-8
/// byte-order mark at its start is skipped.
std::vector<Line> readFields(const std::string& path) {
  std::ifstream in(path);
  if (!in) throw ParseError(path, 0, "cannot open file");
  std::vector<Line> lines;
  std::string text;
  for (int number = 1; std::getline(in, text); ++number) {
    if (number == 1 && text.compare(0, 3, "\xEF\xBB\xBF") == 0) text.erase(0, 3);
    if (text.find('\0') != std::string::npos) {
      throw ParseError(path, number, "the line holds a NUL byte: not a text file");
    }
    std::replace(text.begin(), text.end(), ',', ' ');
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
    CalibratedView view;
    view.name = name;
    view.camera = make_camera();
    view.source = location(path, line.number);
    return view;
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
  CalibratedView view =
      makeView(line.fields[0], line, path, [&] { return PinholeCamera(K, R, t); });
  view.camera_model = "par";
  return view;
}

CalibratedView projectionView(const std::string& name, const Matrix34d& P, const Line& line,
                              const std::string& path) {
  CalibratedView view =
      makeView(name, line, path, [&] { return PinholeCamera::fromProjection(P); });
  view.camera_model = "projection";
  return view;
}

/// Parses the matrix starting at lines[*i] (one line of 12 numbers, or three rows of 4, each form
/// optionally named on its first line or alone on the line before) and moves *i past it.
CalibratedView parseProjection(const std::vector<Line>& lines, size_t* i, const std::string& path) {
  const Line& line = lines[*i];
  const size_t n = line.fields.size();
  std::string name;
  size_t first = 0;
  if (n == 1 && !isNumber(line.fields[0])) {  // a name alone: the matrix follows
    name = line.fields[0];
    if (*i + 1 >= lines.size()) {
      throw ParseError(path, line.number, "the name '" + name + "' is not followed by a matrix");
    }
    ++*i;
    const Line& next = lines[*i];
    if (next.fields.size() != 12 && next.fields.size() != 4) {
      throw ParseError(path, next.number,
                       "expected 12 numbers of a 3x4 matrix or a row of 4 after the name '" + name +
                           "'; found " + std::to_string(next.fields.size()) + " fields");
    }
    if (next.fields.size() == 12) {
      ++*i;
      return projectionView(name, parseMatrix<3, 4>(next, 0, path), next, path);
    }
  } else if (n == 5 && !isNumber(line.fields[0])) {
    name = line.fields[0];
    first = 1;
  } else if (n == 12 || n == 13) {
    first = n - 12;
    if (first == 1 && isNumber(line.fields[0])) {
      throw ParseError(
          path, line.number,
          "expected an image name before the 12 numbers, found '" + line.fields[0] + "'");
    }
    ++*i;
    return projectionView(first == 1 ? line.fields[0] : std::string(),
                          parseMatrix<3, 4>(line, first, path), line, path);
  } else if (n != 4) {
    throw ParseError(path, line.number,
                     "expected 12 numbers of a 3x4 matrix (or a row of 4), optionally after a "
                     "name; found " +
                         std::to_string(n) + " fields");
  }
  // Three rows of 4 numbers, the first at lines[*i] after `first` fields.
  const Line& top = lines[*i];
  Matrix34d P;
  for (int r = 0; r < 3; ++r) {
    if (*i >= lines.size()) {
      throw ParseError(path, lines.back().number,
                       "the file ends inside a matrix: expected 3 rows of 4 numbers");
    }
    const Line& row = lines[*i];
    const size_t skip = r == 0 ? first : 0;
    if (row.fields.size() != 4 + skip) {
      throw ParseError(path, row.number,
                       "expected row " + std::to_string(r + 1) +
                           " of a 3x4 matrix (4 numbers), "
                           "found " +
                           std::to_string(row.fields.size()) + " fields");
    }
    P.row(r) = parseMatrix<1, 4>(row, skip, path);
    ++*i;
  }
  return projectionView(name, P, top, path);
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

/// Throws ParseError naming both lines when two views have the same image name (a view counted
/// twice); `lines[i]` is the line view i starts on. Unnamed views are not compared.
void refuseDuplicateNames(const std::vector<CalibratedView>& views, const std::vector<int>& lines,
                          const std::string& path) {
  std::map<std::string, int> first_line;
  for (size_t i = 0; i < views.size(); ++i) {
    if (views[i].name.empty()) continue;
    const auto [first, inserted] = first_line.emplace(views[i].name, lines[i]);
    if (!inserted) {
      throw ParseError(path, lines[i],
                       "image '" + views[i].name + "' is given twice, on lines " +
                           std::to_string(first->second) + " and " + std::to_string(lines[i]) +
                           ": each view must be listed once");
    }
  }
}

}  // namespace

ParseError::ParseError(const std::string& file, int line, const std::string& message)
    : std::runtime_error(location(file, line) + ": " + message), file_(file), line_(line) {}

std::vector<CalibratedView> readMiddleburyPar(const std::string& path) {
  const std::vector<Line> lines = readFields(path);
  if (lines.empty()) throw ParseError(path, 0, "empty file, expected a count line");
  const int count = parseCount(lines.front(), path);
  std::vector<CalibratedView> views;
  std::vector<int> view_lines;
  for (size_t i = 1; i < lines.size(); ++i) {
    views.push_back(parseParLine(lines[i], path));
    view_lines.push_back(lines[i].number);
  }
  if (static_cast<int>(views.size()) != count) {
    throw ParseError(path, lines.front().number,
                     "count line says " + std::to_string(count) + " views but the file has " +
                         std::to_string(views.size()));
  }
  refuseDuplicateNames(views, view_lines, path);
  return views;
}

std::vector<CalibratedView> readProjectionList(const std::string& path) {
  const std::vector<Line> lines = readFields(path);
  if (lines.empty()) throw ParseError(path, 0, "empty file, expected 3x4 projection matrices");
  std::vector<CalibratedView> views;
  std::vector<int> view_lines;
  for (size_t i = 0; i < lines.size();) {
    view_lines.push_back(lines[i].number);
    views.push_back(parseProjection(lines, &i, path));
  }
  refuseDuplicateNames(views, view_lines, path);
  orientViews(&views, path);
  return views;
}

namespace {

bool isDirectory(const std::string& path) {
  struct stat info;
  return ::stat(path.c_str(), &info) == 0 && S_ISDIR(info.st_mode);
}

bool hasSuffix(const std::string& path, const std::string& suffix) {
  if (path.size() < suffix.size()) return false;
  std::string end = path.substr(path.size() - suffix.size());
  std::transform(end.begin(), end.end(), end.begin(),
                 [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
  return end == suffix;
}

/// Every view of a directory's NeRF files, in the files' order.
std::vector<CalibratedView> readNerfDirectory(const std::vector<std::string>& files) {
  std::vector<CalibratedView> views;
  for (const std::string& file : files) {
    std::vector<CalibratedView> more = readNerfTransforms(file);
    views.insert(views.end(), more.begin(), more.end());
  }
  return views;
}

bool isNpy(const std::string& path) { return hasSuffix(path, ".npy"); }

}  // namespace

std::vector<CalibratedView> readCalibration(const std::string& path) {
  // IDR's views are the images of its image/ sub-directory (readIdrCameras).
  return readCalibrationWithImages(path, idrCamerasFile(path).empty() ? parentDirectory(path) : "");
}

std::string calibrationFormat(const std::string& path) {
  if (isDirectory(path)) {
    if (!nerfTransformFiles(path).empty()) return "NeRF transforms.json";
    if (!idrCamerasFile(path).empty()) return "IDR cameras.npz";
    return colmapModelFormat(path);
  }
  if (isNpy(path)) return "LLFF poses_bounds.npy";
  if (hasSuffix(path, ".npz")) return "IDR cameras.npz";
  if (hasSuffix(path, ".json")) return "NeRF transforms.json";
  try {
    const std::vector<Line> lines = readFields(path);
    if (!lines.empty() && looksLikeCountLine(lines.front())) return "Middlebury par";
  } catch (const ParseError&) {
  }
  return "projection list";
}

std::string describeDistortion(const LensDistortion& d) {
  if (d.isZero()) return "no distortion";
  std::ostringstream text;
  text << std::setprecision(9);
  const std::pair<const char*, double> coefficients[] = {{"k1", d.k1}, {"k2", d.k2}, {"p1", d.p1},
                                                         {"p2", d.p2}, {"k3", d.k3}, {"k4", d.k4},
                                                         {"k5", d.k5}, {"k6", d.k6}};
  const char* separator = "";
  if (d.fisheye) text << "fisheye", separator = " ";
  for (const auto& [name, value] : coefficients) {
    if (value == 0.0) continue;
    text << separator << name << "=" << value;
    separator = " ";
  }
  return text.str();
}

std::vector<CalibratedView> readCalibrationWithImages(const std::string& path,
                                                      const std::string& image_directory) {
  if (isDirectory(path)) {
    const std::vector<std::string> nerf = nerfTransformFiles(path);
    if (!nerf.empty()) return readNerfDirectory(nerf);
    const std::string idr = idrCamerasFile(path);
    if (!idr.empty()) return readIdrCameras(idr, image_directory);
    return readColmapModel(path);
  }
  if (hasSuffix(path, ".json")) return readNerfTransforms(path);
  if (hasSuffix(path, ".npz")) return readIdrCameras(path, image_directory);
  if (isNpy(path)) {
    std::vector<std::string> names;
    try {
      names = listImageFiles(image_directory);
    } catch (const std::runtime_error& e) {
      throw ParseError(path, 0, std::string("the views are the images of ") + e.what());
    }
    // LLFF's downscaled copies keep the full-resolution poses: K follows the images' size.
    const cv::Mat first =
        names.empty() ? cv::Mat()
                      : cv::imread(image_directory + "/" + names.front(), cv::IMREAD_UNCHANGED);
    return readLlffPoses(path, names, first.cols, first.rows);
  }
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
    if (c.distorted()) {
      throw std::runtime_error(path + ": view '" + view.name + "' has lens distortion (" +
                               describeDistortion(c.distortion()) +
                               "), which a par file cannot hold; write a COLMAP model");
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
