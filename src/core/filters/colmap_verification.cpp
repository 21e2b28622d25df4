#include "sift_hull/filters/colmap_verification.h"

#include <sqlite3.h>
#include <stdlib.h>
#include <sys/wait.h>

#include <cerrno>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <map>
#include <memory>
#include <opencv2/imgcodecs.hpp>
#include <sstream>
#include <stdexcept>
#include <vector>

#include "sift_hull/process.h"

namespace sift_hull {
namespace {

namespace fs = std::filesystem;

/// Runs `program arguments...` with stdout and stderr appended to `log`; its exit status, or -1
/// when it could not start.
int run(const std::string& program, const std::vector<std::string>& arguments,
        const fs::path& log) {
  std::vector<std::string> command = {program};
  command.insert(command.end(), arguments.begin(), arguments.end());
  const pid_t child = startProgram(command, log.string(), ProgramOutput::kBothAppendedToFile);
  if (child < 0) return -1;
  int status = 0;
  while (waitpid(child, &status, 0) < 0) {
    if (errno != EINTR) return -1;
  }
  return WIFEXITED(status) ? WEXITSTATUS(status) : 128 + WTERMSIG(status);
}

/// The last lines of a log, for an error message.
std::string logTail(const fs::path& log) {
  std::ifstream in(log);
  std::vector<std::string> lines;
  for (std::string line; std::getline(in, line);) {
    if (!line.empty()) lines.push_back(line);
  }
  std::string tail;
  for (size_t i = lines.size() > 4 ? lines.size() - 4 : 0; i < lines.size(); ++i) {
    tail += (tail.empty() ? "" : " | ") + lines[i];
  }
  return tail;
}

/// A directory of its own, removed with it.
class TemporaryDirectory {
 public:
  TemporaryDirectory() {
    std::string pattern = (fs::temp_directory_path() / "sift_hull_colmap_XXXXXX").string();
    if (mkdtemp(pattern.data()) == nullptr) {
      throw std::runtime_error("colmap filter: cannot make a temporary directory");
    }
    path_ = pattern;
  }
  ~TemporaryDirectory() {
    std::error_code ignored;
    fs::remove_all(path_, ignored);
  }
  const fs::path& path() const { return path_; }

 private:
  fs::path path_;
};

/// A keypoint file of COLMAP's text format: "N 128", then x y scale orientation and 128 zeros.
void writeKeypoints(const fs::path& path, const std::vector<cv::KeyPoint>& keypoints) {
  std::ofstream out(path);
  out << keypoints.size() << " 128\n";
  std::string zeros;
  for (int d = 0; d < 128; ++d) zeros += " 0";
  constexpr double kDegToRad = 3.14159265358979323846 / 180.0;
  for (const cv::KeyPoint& k : keypoints) {
    // Non-finite points are written at the origin: no match of theirs is imported.
    const bool finite = std::isfinite(k.pt.x) && std::isfinite(k.pt.y);
    out << (finite ? k.pt.x + 0.5 : 0.0) << ' ' << (finite ? k.pt.y + 0.5 : 0.0) << ' '
        << (std::isfinite(k.size) && k.size > 0.0f ? k.size / 2.0 : 1.0) << ' '
        << (std::isfinite(k.angle) ? k.angle * kDegToRad : 0.0) << zeros << '\n';
  }
  if (!out) throw std::runtime_error(path.string() + ": cannot write");
}

/// COLMAP's image id of each image name, and the verified pairs' inliers as stored (image ids
/// ascending in pair_id; the blob's columns in that order).
struct Verified {
  std::map<std::string, int64_t> image_ids;
  std::vector<std::pair<uint32_t, uint32_t>> inliers;  ///< (first image's, second's) keypoints
  int64_t first_image = -1;
};

Verified readDatabase(const fs::path& database) {
  sqlite3* raw = nullptr;
  if (sqlite3_open_v2(database.c_str(), &raw, SQLITE_OPEN_READONLY, nullptr) != SQLITE_OK) {
    sqlite3_close(raw);
    throw std::runtime_error("colmap filter: cannot open the database COLMAP wrote");
  }
  const std::unique_ptr<sqlite3, int (*)(sqlite3*)> db(raw, sqlite3_close);
  Verified verified;
  const auto query = [&](const char* sql, const auto& row) {
    sqlite3_stmt* statement = nullptr;
    if (sqlite3_prepare_v2(db.get(), sql, -1, &statement, nullptr) != SQLITE_OK) {
      throw std::runtime_error(std::string("colmap filter: ") + sqlite3_errmsg(db.get()));
    }
    while (sqlite3_step(statement) == SQLITE_ROW) row(statement);
    sqlite3_finalize(statement);
  };
  query("SELECT image_id, name FROM images", [&](sqlite3_stmt* s) {
    verified.image_ids[reinterpret_cast<const char*>(sqlite3_column_text(s, 1))] =
        sqlite3_column_int64(s, 0);
  });
  query("SELECT pair_id, rows, cols, data FROM two_view_geometries", [&](sqlite3_stmt* s) {
    constexpr int64_t kMaxImages = 2147483647;
    verified.first_image = sqlite3_column_int64(s, 0) / kMaxImages;
    const int64_t rows = sqlite3_column_int64(s, 1), cols = sqlite3_column_int64(s, 2);
    const void* data = sqlite3_column_blob(s, 3);
    const int64_t bytes = sqlite3_column_bytes(s, 3);
    if (rows <= 0 || cols != 2 || data == nullptr || bytes != rows * 2 * 4) return;
    std::vector<uint32_t> values(static_cast<size_t>(rows) * 2);
    std::memcpy(values.data(), data, static_cast<size_t>(bytes));
    for (size_t r = 0; r < static_cast<size_t>(rows); ++r) {
      verified.inliers.emplace_back(values[2 * r], values[2 * r + 1]);
    }
  });
  return verified;
}

}  // namespace

bool colmapAvailable(const std::string& program, std::string* why_not) {
  const TemporaryDirectory directory;
  const int status = run(program, {"help"}, directory.path() / "log.txt");
  if (status == 0) return true;
  if (why_not != nullptr) {
    *why_not = status < 0 ? program + ": not found on PATH; install the Debian package colmap"
                          : program + " help: exit status " + std::to_string(status);
  }
  return false;
}

FilterResult filterColmap(const PutativeMatches& input, const ColmapConfig& config) {
  FilterResult result = FilterResult::keepingNone(input.matches.size());
  for (size_t m = 0; m < input.matches.size(); ++m) {
    if (input.hasFinitePositions(m)) result.score[m] = 1.0;
  }
  if (input.left_image_size.empty() || input.right_image_size.empty()) {
    throw std::invalid_argument("colmap filter: the putative matches carry no image sizes");
  }
  std::string why_not;
  if (!colmapAvailable(config.program, &why_not)) {
    throw std::runtime_error("colmap filter: " + why_not);
  }
  const TemporaryDirectory directory;
  const fs::path images = directory.path() / "images", features = directory.path() / "features";
  fs::create_directory(images);
  fs::create_directory(features);
  // COLMAP reads each image for its size: blank ones of the images' sizes do.
  const std::string left = "left.png", right = "right.png";
  if (!cv::imwrite((images / left).string(), cv::Mat::zeros(input.left_image_size, CV_8UC1)) ||
      !cv::imwrite((images / right).string(), cv::Mat::zeros(input.right_image_size, CV_8UC1))) {
    throw std::runtime_error("colmap filter: cannot write its images");
  }
  writeKeypoints(features / (left + ".txt"), input.left_keypoints);
  writeKeypoints(features / (right + ".txt"), input.right_keypoints);
  std::multimap<std::pair<uint32_t, uint32_t>, size_t> index;
  {
    std::ofstream list(directory.path() / "matches.txt");
    list << left << ' ' << right << '\n';
    for (size_t m = 0; m < input.matches.size(); ++m) {
      if (!input.hasFinitePositions(m)) continue;
      const auto key = std::make_pair(static_cast<uint32_t>(input.matches[m].queryIdx),
                                      static_cast<uint32_t>(input.matches[m].trainIdx));
      if (index.count(key) == 0) list << key.first << ' ' << key.second << '\n';
      index.emplace(key, m);
    }
    list << '\n';
    if (!list) throw std::runtime_error("colmap filter: cannot write its match list");
  }
  const fs::path database = directory.path() / "database.db", log = directory.path() / "log.txt";
  const std::string seed = std::to_string(config.seed);
  if (run(config.program,
          {"feature_importer", "--random_seed", seed, "--database_path", database.string(),
           "--image_path", images.string(), "--import_path", features.string()},
          log) != 0) {
    throw std::runtime_error("colmap feature_importer failed: " + logTail(log));
  }
  if (run(config.program,
          {"matches_importer", "--random_seed", seed, "--database_path", database.string(),
           "--match_list_path", (directory.path() / "matches.txt").string(), "--match_type", "raw",
           "--SiftMatching.use_gpu", "0", "--SiftMatching.num_threads",
           std::to_string(config.threads)},
          log) != 0) {
    throw std::runtime_error("colmap matches_importer failed: " + logTail(log));
  }
  const Verified verified = readDatabase(database);
  const auto left_id = verified.image_ids.find(left), right_id = verified.image_ids.find(right);
  if (left_id == verified.image_ids.end() || right_id == verified.image_ids.end()) {
    throw std::runtime_error("colmap filter: COLMAP did not import both images: " + logTail(log));
  }
  const bool swapped = verified.first_image == right_id->second;
  for (auto [a, b] : verified.inliers) {
    if (swapped) std::swap(a, b);
    const auto range = index.equal_range({a, b});
    for (auto it = range.first; it != range.second; ++it) {
      result.keep[it->second] = 1;
      result.score[it->second] = 0.0;
    }
  }
  return result;
}

}  // namespace sift_hull
