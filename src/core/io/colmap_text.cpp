// COLMAP's text model (cameras.txt, images.txt), read a character at a time: a line's first words
// are kept and the rest only checked and counted, so that the POINTS2D lines of a large
// images.txt (three words per 2-D point) cost no memory.

#include <algorithm>
#include <cctype>
#include <cmath>
#include <cstdlib>
#include <fstream>

#include "colmap_internal.h"
#include "sift_hull/limits.h"

namespace sift_hull {
namespace colmap_detail {
namespace {

/// Words kept of a line: a camera line has at most 4 + 16 (RAD_TAN_THIN_PRISM_FISHEYE), an image
/// line 10.
constexpr size_t kKeptWords = 24;
/// Fields of an image line: IMAGE_ID QW QX QY QZ TX TY TZ CAMERA_ID NAME. Never a POINTS2D line,
/// which has three words per point.
constexpr size_t kImageLineWords = 10;

/// A line of a text file: its first kKeptWords words, how many words it has, and whether they
/// read as POINTS2D triples (X Y POINT3D_ID: two numbers and an integer, -1 for no 3-D point).
struct ScannedLine {
  int number = 0;
  std::vector<std::string> words;
  size_t word_count = 0;
  bool point_triples = true;
};

bool isNumberWord(const std::string& word) {
  char* end = nullptr;
  const double value = std::strtod(word.c_str(), &end);
  return end == word.c_str() + word.size() && std::isfinite(value);
}

bool isPointIdWord(const std::string& word) {
  const size_t first = word[0] == '-' ? 1 : 0;
  if (first == 1) return word == "-1";
  return word.size() <= 20 && word.find_first_not_of("0123456789") == std::string::npos;
}

/// The non-comment lines of a text file ('#' first), one at a time; a UTF-8 byte-order mark at
/// the start is skipped.
class LineScanner {
 public:
  explicit LineScanner(const std::string& path) : in_(path, std::ios::binary), path_(path) {
    if (!in_) throw ParseError(path, 0, "cannot open file");
    const char bom[3] = {'\xEF', '\xBB', '\xBF'};
    char start[3] = {0, 0, 0};
    in_.read(start, 3);
    if (in_.gcount() != 3 || !std::equal(start, start + 3, bom)) {
      in_.clear();
      in_.seekg(0);
    }
  }

  /// The next line that is not a comment; false at the end of the file.
  bool next(ScannedLine* line) {
    while (readLine(line)) {
      if (line->words.empty() || line->words.front()[0] != '#') return true;
    }
    return false;
  }

 private:
  bool readLine(ScannedLine* line) {
    std::streambuf* buffer = in_.rdbuf();
    int c = buffer->sbumpc();
    if (c == std::char_traits<char>::eof()) return false;
    *line = ScannedLine();
    line->number = ++number_;
    for (; c != std::char_traits<char>::eof() && c != '\n'; c = buffer->sbumpc()) {
      if (c == '\0') throw ParseError(path_, number_, "the line holds a NUL byte: not a text file");
      if (std::isspace(c)) {
        endWord(line);
      } else if (word_.size() >= limits::kMaxImageNameChars) {
        throw ParseError(path_, number_, "a word longer than 4096 bytes");
      } else {
        word_.push_back(static_cast<char>(c));
      }
    }
    endWord(line);
    return true;
  }

  void endWord(ScannedLine* line) {
    if (word_.empty()) return;
    if (line->point_triples) {
      line->point_triples = line->word_count % 3 == 2 ? isPointIdWord(word_) : isNumberWord(word_);
    }
    if (line->words.size() < kKeptWords) line->words.push_back(word_);
    ++line->word_count;
    word_.clear();
  }

  std::ifstream in_;
  std::string path_;
  std::string word_;  ///< the word being read, its buffer reused
  int number_ = 0;
};

double textNumber(const std::string& word, const std::string& file, int line) {
  char* end = nullptr;
  const double value = std::strtod(word.c_str(), &end);
  if (word.empty() || end != word.c_str() + word.size()) {
    throw ParseError(file, line, "'" + word + "' is not a number");
  }
  if (!std::isfinite(value)) throw ParseError(file, line, "'" + word + "' is not finite");
  return value;
}

uint64_t textInteger(const std::string& word, uint64_t max, const std::string& file, int line) {
  if (word.empty() || word.find_first_not_of("0123456789") != std::string::npos ||
      word.size() > 12 || std::strtoull(word.c_str(), nullptr, 10) > max) {
    throw ParseError(file, line, "'" + word + "' is not an integer in 0.." + std::to_string(max));
  }
  return std::strtoull(word.c_str(), nullptr, 10);
}

/// The camera of a line of cameras.txt, its id in *id.
ColmapCamera cameraOfLine(const ScannedLine& line, const std::string& file, uint32_t* id) {
  const std::vector<std::string>& fields = line.words;
  if (line.word_count < 4) {
    throw ParseError(file, line.number,
                     "expected CAMERA_ID MODEL WIDTH HEIGHT PARAMS..., found " +
                         std::to_string(line.word_count) + " fields");
  }
  *id = static_cast<uint32_t>(textInteger(fields[0], UINT32_MAX, file, line.number));
  const ModelInfo* model = modelByName(fields[1]);
  if (model == nullptr) {
    throw ParseError(file, line.number, "unknown camera model '" + fields[1] + "'");
  }
  if (line.word_count > fields.size()) {
    throw ParseError(file, line.number,
                     std::string("camera model ") + model->name + " has " +
                         std::to_string(model->params) + " parameters, found " +
                         std::to_string(line.word_count - 4));
  }
  const uint64_t width = textInteger(fields[2], UINT32_MAX, file, line.number);
  const uint64_t height = textInteger(fields[3], UINT32_MAX, file, line.number);
  std::vector<double> params;
  for (size_t i = 4; i < fields.size(); ++i) {
    params.push_back(textNumber(fields[i], file, line.number));
  }
  return makeCamera(*model, width, height, params, file, line.number,
                    file + ":" + std::to_string(line.number));
}

CalibratedView viewOfLine(const ScannedLine& line, const std::string& file,
                          const std::map<uint32_t, ColmapCamera>& cameras) {
  const std::vector<std::string>& fields = line.words;
  textInteger(fields[0], UINT32_MAX, file, line.number);
  double q[4], t[3];
  for (int k = 0; k < 4; ++k) q[k] = textNumber(fields[1 + k], file, line.number);
  for (int k = 0; k < 3; ++k) t[k] = textNumber(fields[5 + k], file, line.number);
  const uint32_t camera_id =
      static_cast<uint32_t>(textInteger(fields[8], UINT32_MAX, file, line.number));
  return makeView(fields[9], q, t, camera_id, cameras, file, line.number,
                  file + ":" + std::to_string(line.number));
}

/// Throws for a line of images.txt that is neither an image line nor, right after one, its
/// POINTS2D line.
[[noreturn]] void refuseImagesLine(const ScannedLine& line, bool after_image,
                                   const std::string& file) {
  const std::string found = "found " + std::to_string(line.word_count) + " fields";
  if (!after_image) {
    throw ParseError(file, line.number,
                     "expected IMAGE_ID QW QX QY QZ TX TY TZ CAMERA_ID NAME, " + found);
  }
  throw ParseError(file, line.number,
                   "expected the POINTS2D line of the image above (X Y POINT3D_ID per point: "
                   "two numbers and an integer) or the next IMAGE_ID QW QX QY QZ TX TY TZ "
                   "CAMERA_ID NAME; " +
                       found);
}

}  // namespace

std::map<uint32_t, ColmapCamera> readCamerasText(const std::string& file) {
  LineScanner scanner(file);
  std::map<uint32_t, ColmapCamera> cameras;
  for (ScannedLine line; scanner.next(&line);) {
    if (line.word_count == 0) continue;
    uint32_t id = 0;
    ColmapCamera camera = cameraOfLine(line, file, &id);
    if (cameras.count(id)) {
      throw ParseError(file, line.number, "camera " + std::to_string(id) + " given twice");
    }
    if (cameras.size() >= limits::kMaxCalibrationViews) {
      throw ParseError(file, line.number, "more cameras than the limit of 1000000");
    }
    cameras[id] = std::move(camera);
  }
  if (cameras.empty()) throw ParseError(file, 0, "no cameras");
  return cameras;
}

std::vector<CalibratedView> readImagesText(const std::string& file,
                                           const std::map<uint32_t, ColmapCamera>& cameras) {
  LineScanner scanner(file);
  std::vector<CalibratedView> views;
  bool after_image = false;  // the line after an image line may be its POINTS2D line
  for (ScannedLine line; scanner.next(&line);) {
    if (line.word_count == kImageLineWords) {
      if (views.size() >= limits::kMaxCalibrationViews) {
        throw ParseError(file, line.number, "more images than the limit of 1000000");
      }
      views.push_back(viewOfLine(line, file, cameras));
      after_image = true;
    } else if (after_image && line.word_count % 3 == 0 && line.point_triples) {
      after_image = false;  // its POINTS2D line, empty or not: checked, nothing kept
    } else if (line.word_count != 0) {
      refuseImagesLine(line, after_image, file);
    }
  }
  return views;
}

}  // namespace colmap_detail
}  // namespace sift_hull
