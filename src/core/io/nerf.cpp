// NeRF / instant-ngp transforms.json (sift_hull/io/nerf.h).

#include "sift_hull/io/nerf.h"

#include <sys/stat.h>

#include <Eigen/Dense>
#include <cmath>
#include <fstream>
#include <iomanip>
#include <nlohmann/json.hpp>
#include <opencv2/imgcodecs.hpp>
#include <optional>
#include <sstream>

#include "sift_hull/limits.h"

namespace sift_hull {
namespace {

using Json = nlohmann::json;

/// Files larger than this are refused before parsing (a million frames take about 400 MB).
constexpr uint64_t kMaxFileBytes = uint64_t{1} << 30;

bool isFile(const std::string& path) {
  struct stat info;
  return ::stat(path.c_str(), &info) == 0 && S_ISREG(info.st_mode);
}

[[noreturn]] void fail(const std::string& file, const std::string& message) {
  throw ParseError(file, 0, message);
}

/// The frame's value of `key`, else the file's; nullptr when neither has it.
const Json* lookUp(const Json& frame, const Json& root, const char* key) {
  if (frame.contains(key)) return &frame.at(key);
  if (root.contains(key)) return &root.at(key);
  return nullptr;
}

/// A finite number, or the error names where and what.
double number(const Json& value, const std::string& file, const std::string& where,
              const std::string& key) {
  if (!value.is_number()) fail(file, where + ": \"" + key + "\" is not a number");
  const double x = value.get<double>();
  if (!std::isfinite(x)) fail(file, where + ": \"" + key + "\" is not finite");
  return x;
}

/// The image file a frame's file_path names, relative to `directory`: as written, or with the
/// first extension that exists (NeRF's synthetic scenes write "./train/r_0").
std::string imageName(std::string file_path, const std::string& directory) {
  while (file_path.rfind("./", 0) == 0) file_path.erase(0, 2);
  if (isFile(directory + "/" + file_path)) return file_path;
  const std::string::size_type slash = file_path.find_last_of('/');
  const std::string::size_type dot = file_path.find_last_of('.');
  const bool has_extension =
      dot != std::string::npos && (slash == std::string::npos || dot > slash);
  if (!has_extension) {
    for (const char* extension : {".png", ".jpg", ".jpeg", ".PNG", ".JPG"}) {
      if (isFile(directory + "/" + file_path + extension)) return file_path + extension;
    }
    return file_path + ".png";
  }
  return file_path;
}

std::vector<CalibratedView> readFile(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  struct stat info;
  if (!in || ::stat(path.c_str(), &info) != 0 || !S_ISREG(info.st_mode)) {
    fail(path, "cannot open file");
  }
  if (static_cast<uint64_t>(info.st_size) > kMaxFileBytes) fail(path, "larger than 1 GiB");
  Json root;
  try {
    root = Json::parse(in);
  } catch (const Json::exception& e) {
    fail(path, std::string("not valid JSON: ") + e.what());
  }
  if (!root.is_object()) fail(path, "not a JSON object");
  if (!root.contains("frames") || !root.at("frames").is_array()) {
    fail(path, "no \"frames\" array (not a NeRF transforms.json)");
  }
  const Json& frames = root.at("frames");
  if (frames.empty()) fail(path, "\"frames\" is empty");
  if (frames.size() > limits::kMaxCalibrationViews) {
    fail(path, "more than " + std::to_string(limits::kMaxCalibrationViews) + " frames");
  }
  const std::string directory = parentDirectory(path);
  std::vector<CalibratedView> views;
  views.reserve(frames.size());
  for (size_t i = 0; i < frames.size(); ++i) {
    const Json& frame = frames[i];
    std::string where = "frame " + std::to_string(i);
    if (!frame.is_object()) fail(path, where + ": not a JSON object");
    if (!frame.contains("file_path") || !frame.at("file_path").is_string()) {
      fail(path, where + ": no \"file_path\" string");
    }
    const std::string file_path = frame.at("file_path").get<std::string>();
    if (file_path.empty() || file_path.size() > limits::kMaxImageNameChars) {
      fail(path, where + ": \"file_path\" must hold 1 to " +
                     std::to_string(limits::kMaxImageNameChars) + " characters");
    }
    const std::string name = imageName(file_path, directory);
    where += " (" + name + ")";
    const auto get = [&](const char* key) -> std::optional<double> {
      const Json* value = lookUp(frame, root, key);
      if (value == nullptr) return std::nullopt;
      return number(*value, path, where, key);
    };
    // The image's size: the json's, else the file's.
    std::optional<double> w = get("w"), h = get("h");
    if (!w || !h) {
      // Only a regular file is decoded: a device or a fifo named by file_path would block.
      const std::string image_path = directory + "/" + name;
      const cv::Mat image =
          isFile(image_path) ? cv::imread(image_path, cv::IMREAD_UNCHANGED) : cv::Mat();
      if (image.empty()) {
        fail(path, where + ": no \"w\" and \"h\", and the image cannot be read for its size");
      }
      if (!w) w = image.cols;
      if (!h) h = image.rows;
    }
    const double side_max = static_cast<double>(limits::kMaxImageSidePx);
    if (!(*w >= 1.0 && *h >= 1.0 && *w <= side_max && *h <= side_max)) {
      fail(path, where + ": \"w\" and \"h\" must lie in [1, 65536]");
    }
    std::optional<double> fx = get("fl_x"), fy = get("fl_y");
    if (!fx) {
      const std::optional<double> angle = get("camera_angle_x");
      if (!angle) fail(path, where + ": neither \"fl_x\" nor \"camera_angle_x\"");
      if (!(*angle > 0.0 && *angle < M_PI)) {
        fail(path, where + ": \"camera_angle_x\" must lie in (0, pi) radians");
      }
      fx = 0.5 * *w / std::tan(0.5 * *angle);
    }
    if (!fy) {
      const std::optional<double> angle = get("camera_angle_y");
      if (angle && !(*angle > 0.0 && *angle < M_PI)) {
        fail(path, where + ": \"camera_angle_y\" must lie in (0, pi) radians");
      }
      fy = angle ? 0.5 * *h / std::tan(0.5 * *angle) : *fx;
    }
    if (!(*fx > 0.0 && *fy > 0.0)) fail(path, where + ": the focal lengths must be positive");
    const double cx = get("cx").value_or(0.5 * *w) - 0.5;
    const double cy = get("cy").value_or(0.5 * *h) - 0.5;
    Eigen::Matrix3d K;
    K << *fx, 0.0, cx, 0.0, *fy, cy, 0.0, 0.0, 1.0;

    if (!frame.contains("transform_matrix")) fail(path, where + ": no \"transform_matrix\"");
    const Json& rows = frame.at("transform_matrix");
    if (!rows.is_array() || (rows.size() != 4 && rows.size() != 3)) {
      fail(path, where + ": \"transform_matrix\" must be 4 rows (or 3) of 4 numbers");
    }
    Eigen::Matrix4d T = Eigen::Matrix4d::Identity();
    for (size_t r = 0; r < rows.size(); ++r) {
      if (!rows[r].is_array() || rows[r].size() != 4) {
        fail(path, where + ": \"transform_matrix\" must be 4 rows (or 3) of 4 numbers");
      }
      for (size_t c = 0; c < 4; ++c) {
        T(static_cast<int>(r), static_cast<int>(c)) =
            number(rows[r][c], path, where, "transform_matrix");
      }
    }
    if ((T.row(3) - Eigen::RowVector4d(0, 0, 0, 1)).cwiseAbs().maxCoeff() > 1e-6) {
      fail(path, where + ": \"transform_matrix\"'s last row is not 0 0 0 1");
    }
    // OpenGL's camera axes [right, up, backwards] into OpenCV's [right, down, forwards].
    const Eigen::Matrix3d R_c2w = T.topLeftCorner<3, 3>() * Eigen::Vector3d(1, -1, -1).asDiagonal();
    CalibratedView view;
    view.name = name;
    view.source = path + " (" + where + ")";
    view.camera_model = "NeRF";
    view.width_px = static_cast<uint64_t>(std::lround(*w));
    view.height_px = static_cast<uint64_t>(std::lround(*h));
    view.size_source = view.source;
    try {
      view.camera = PinholeCamera::fromCentre(K, R_c2w.transpose(), T.topRightCorner<3, 1>());
      LensDistortion distortion;
      distortion.k1 = get("k1").value_or(0.0);
      distortion.k2 = get("k2").value_or(0.0);
      distortion.p1 = get("p1").value_or(0.0);
      distortion.p2 = get("p2").value_or(0.0);
      if (!distortion.isZero()) view.camera = view.camera.withDistortion(distortion);
    } catch (const std::invalid_argument& e) {
      fail(path, where + ": " + e.what() + " (\"transform_matrix\" must be a rigid transform)");
    }
    views.push_back(view);
  }
  return views;
}

}  // namespace

std::vector<CalibratedView> readNerfTransforms(const std::string& path) { return readFile(path); }

std::vector<std::string> nerfTransformFiles(const std::string& directory) {
  for (const char* colmap : {"cameras.bin", "cameras.txt"}) {
    if (isFile(directory + "/" + colmap)) return {};
  }
  if (isFile(directory + "/transforms.json")) return {directory + "/transforms.json"};
  std::vector<std::string> files;
  for (const char* split : {"train", "val", "test"}) {
    const std::string file = directory + "/transforms_" + split + ".json";
    if (isFile(file)) files.push_back(file);
  }
  return files;
}

void writeNerfTransforms(const std::string& path, const std::vector<CalibratedView>& views,
                         int width_px, int height_px) {
  Json frames = Json::array();
  for (const CalibratedView& view : views) {
    const PinholeCamera& camera = view.camera;
    const Eigen::Matrix3d& K = camera.K();
    const LensDistortion& d = camera.distortion();
    if (camera.improper() || K(0, 1) != 0.0 || d.fisheye || d.k3 != 0.0 || d.k4 != 0.0 ||
        d.k5 != 0.0 || d.k6 != 0.0) {
      throw std::runtime_error(path + ": view '" + view.name +
                               "' has a skewed K, a mirrored world frame or distortion beyond "
                               "k1, k2, p1, p2, which transforms.json cannot hold");
    }
    Eigen::Matrix4d T = Eigen::Matrix4d::Identity();
    T.topLeftCorner<3, 3>() = camera.R().transpose() * Eigen::Vector3d(1, -1, -1).asDiagonal();
    T.topRightCorner<3, 1>() = camera.centre();
    Json rows = Json::array();
    for (int r = 0; r < 4; ++r) rows.push_back({T(r, 0), T(r, 1), T(r, 2), T(r, 3)});
    frames.push_back({{"file_path", view.name},
                      {"transform_matrix", rows},
                      {"fl_x", K(0, 0)},
                      {"fl_y", K(1, 1)},
                      {"cx", K(0, 2) + 0.5},
                      {"cy", K(1, 2) + 0.5},
                      {"w", width_px},
                      {"h", height_px},
                      {"k1", d.k1},
                      {"k2", d.k2},
                      {"p1", d.p1},
                      {"p2", d.p2}});
  }
  std::ofstream out(path);
  if (!out) throw std::runtime_error(path + ": cannot write file");
  out << std::setprecision(17) << Json{{"frames", frames}}.dump(2) << '\n';
  if (!out) throw std::runtime_error(path + ": cannot write file");
}

}  // namespace sift_hull
