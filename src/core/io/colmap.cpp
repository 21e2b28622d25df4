#include "sift_hull/io/colmap.h"

#include <sys/stat.h>

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <cstring>
#include <fstream>
#include <iomanip>
#include <set>
#include <sstream>

#include "colmap_internal.h"
#include "sift_hull/limits.h"

namespace sift_hull {
namespace colmap_detail {
namespace {

// COLMAP's camera models (colmap/sensor/models.h), id, name and number of parameters.
constexpr ModelInfo kModels[] = {
    {0, "SIMPLE_PINHOLE", 3, true},
    {1, "PINHOLE", 4, true},
    {2, "SIMPLE_RADIAL", 4, true},
    {3, "RADIAL", 5, true},
    {4, "OPENCV", 8, true},
    {5, "OPENCV_FISHEYE", 8, true},
    {6, "FULL_OPENCV", 12, true},
    {7, "FOV", 5, false},
    {8, "SIMPLE_RADIAL_FISHEYE", 4, false},
    {9, "RADIAL_FISHEYE", 5, false},
    {10, "THIN_PRISM_FISHEYE", 12, false},
    {11, "RAD_TAN_THIN_PRISM_FISHEYE", 16, false},
};

}  // namespace

const ModelInfo* modelById(int64_t id) {
  for (const ModelInfo& m : kModels) {
    if (m.id == id) return &m;
  }
  return nullptr;
}

const ModelInfo* modelByName(const std::string& name) {
  for (const ModelInfo& m : kModels) {
    if (name == m.name) return &m;
  }
  return nullptr;
}

ColmapCamera makeCamera(const ModelInfo& model, uint64_t width, uint64_t height,
                        const std::vector<double>& p, const std::string& file, int line,
                        const std::string& source) {
  if (!model.supported) {
    throw ParseError(file, line,
                     std::string("camera model ") + model.name +
                         " is not supported (SIMPLE_PINHOLE, PINHOLE, SIMPLE_RADIAL, RADIAL, "
                         "OPENCV, OPENCV_FISHEYE, FULL_OPENCV are)");
  }
  if (static_cast<int>(p.size()) != model.params) {
    throw ParseError(file, line,
                     std::string("camera model ") + model.name + " has " +
                         std::to_string(model.params) + " parameters, found " +
                         std::to_string(p.size()));
  }
  for (double v : p) {
    if (!std::isfinite(v)) throw ParseError(file, line, "a camera parameter is not finite");
  }
  if (width < 1 || height < 1 || width > limits::kMaxImageSidePx ||
      height > limits::kMaxImageSidePx) {
    throw ParseError(file, line,
                     "image size " + std::to_string(width) + "x" + std::to_string(height) +
                         " outside 1.." + std::to_string(limits::kMaxImageSidePx));
  }
  ColmapCamera camera;
  camera.model = model.name;
  camera.width_px = width;
  camera.height_px = height;
  camera.source = source;
  const std::string name = model.name;
  const bool one_focal = name == "SIMPLE_PINHOLE" || name == "SIMPLE_RADIAL" || name == "RADIAL";
  const double fx = p[0];
  const double fy = one_focal ? p[0] : p[1];
  const double cx = one_focal ? p[1] : p[2];
  const double cy = one_focal ? p[2] : p[3];
  if (!(fx > 0.0) || !(fy > 0.0)) throw ParseError(file, line, "focal lengths must be positive");
  // COLMAP's pixel (0, 0) is the top-left image corner; here it is the top-left pixel's centre.
  camera.K << fx, 0.0, cx - 0.5, 0.0, fy, cy - 0.5, 0.0, 0.0, 1.0;
  LensDistortion& d = camera.distortion;
  if (name == "SIMPLE_RADIAL") d.k1 = p[3];
  if (name == "RADIAL") {
    d.k1 = p[3];
    d.k2 = p[4];
  }
  if (name == "OPENCV" || name == "FULL_OPENCV") {
    d.k1 = p[4];
    d.k2 = p[5];
    d.p1 = p[6];
    d.p2 = p[7];
  }
  if (name == "OPENCV_FISHEYE") {
    d.fisheye = true;
    d.k1 = p[4], d.k2 = p[5], d.k3 = p[6], d.k4 = p[7];
  }
  if (name == "FULL_OPENCV") {
    d.k3 = p[8];
    d.k4 = p[9];
    d.k5 = p[10];
    d.k6 = p[11];
  }
  return camera;
}

namespace {

/// How far from 1 a quaternion's norm may be: within it the quaternion is normalised, as COLMAP
/// does (its files hold rounded numbers); further from 1 it is refused, as a quaternion scaled by
/// a wrong column or unit is no rotation as written.
constexpr double kQuaternionNormTolerance = 0.01;

/// The unit quaternion of q (w, x, y, z), or a ParseError at (file, line) naming its norm.
Eigen::Quaterniond unitQuaternion(const double q[4], const std::string& file, int line) {
  for (int i = 0; i < 4; ++i) {
    if (!std::isfinite(q[i])) throw ParseError(file, line, "the quaternion is not finite");
  }
  const Eigen::Quaterniond quaternion(q[0], q[1], q[2], q[3]);
  const double norm = quaternion.norm();
  if (!(std::abs(norm - 1.0) <= kQuaternionNormTolerance)) {
    std::ostringstream message;
    message << std::setprecision(9) << "the quaternion (" << q[0] << ", " << q[1] << ", " << q[2]
            << ", " << q[3] << ") is not of unit length: its norm is " << norm << " (1 to within "
            << kQuaternionNormTolerance << " is normalised)";
    throw ParseError(file, line, message.str());
  }
  return quaternion.normalized();
}

}  // namespace

CalibratedView makeView(const std::string& name, const double q[4], const double t[3],
                        uint32_t camera_id, const std::map<uint32_t, ColmapCamera>& cameras,
                        const std::string& file, int line, const std::string& source) {
  const Eigen::Quaterniond quaternion = unitQuaternion(q, file, line);
  for (int i = 0; i < 3; ++i) {
    if (!std::isfinite(t[i])) throw ParseError(file, line, "the translation is not finite");
  }
  const auto camera = cameras.find(camera_id);
  if (camera == cameras.end()) {
    throw ParseError(file, line,
                     "image '" + name + "' names camera " + std::to_string(camera_id) +
                         ", which the cameras file does not hold");
  }
  if (name.empty()) throw ParseError(file, line, "the image has no name");
  CalibratedView view;
  view.name = name;
  view.source = source;
  view.camera_model = camera->second.model;
  view.width_px = camera->second.width_px;
  view.height_px = camera->second.height_px;
  view.size_source = camera->second.source;
  try {
    view.camera = PinholeCamera(camera->second.K, quaternion.toRotationMatrix(),
                                Eigen::Vector3d(t[0], t[1], t[2]))
                      .withDistortion(camera->second.distortion);
  } catch (const std::invalid_argument& e) {
    throw ParseError(file, line, e.what());
  }
  return view;
}

}  // namespace colmap_detail

namespace {

using colmap_detail::ModelInfo;

bool fileExists(const std::string& path) {
  struct stat info;
  return ::stat(path.c_str(), &info) == 0 && S_ISREG(info.st_mode);
}

// ---- binary model -------------------------------------------------------------------------------

/// Little-endian reads from a stream of known size; every read past the end is a ParseError.
class BinaryReader {
 public:
  BinaryReader(std::istream& in, uint64_t size, const std::string& file)
      : in_(in), size_(size), file_(file) {}
  uint64_t remaining() const { return size_ - offset_; }
  uint64_t offset() const { return offset_; }
  void bytes(void* out, uint64_t n, const char* what) {
    if (n > remaining() || !in_.read(static_cast<char*>(out), static_cast<std::streamsize>(n))) {
      fail(std::string("truncated: ") + what + " at byte " + std::to_string(offset_) +
           " runs past the end of the file");
    }
    offset_ += n;
  }
  template <typename T>
  T read(const char* what) {
    unsigned char raw[sizeof(T)];
    bytes(raw, sizeof(T), what);
    T value;
    std::memcpy(&value, raw, sizeof(T));  // the package builds for little-endian hosts only
    return value;
  }
  void skip(uint64_t n, const char* what) {
    if (n > remaining()) {
      fail(std::string("truncated: ") + what + " at byte " + std::to_string(offset_) +
           " runs past the end of the file");
    }
    in_.seekg(static_cast<std::streamoff>(n), std::ios::cur);
    if (!in_) fail("seek failed");
    offset_ += n;
  }
  std::string name() {
    std::string text;
    for (char c = read<char>("an image name"); c != '\0'; c = read<char>("an image name")) {
      if (text.size() >= limits::kMaxImageNameChars) fail("an image name longer than 4096 bytes");
      text.push_back(c);
    }
    return text;
  }
  /// Throws when `count` records of at least `min_bytes` each cannot fit in the rest of the file.
  void requireFits(uint64_t count, uint64_t min_bytes, const char* what) {
    if (count > limits::kMaxCalibrationViews && std::string(what) != "points") {
      fail(std::string("the file announces ") + std::to_string(count) + " " + what +
           ", more than the limit of 1000000");
    }
    if (count > remaining() / min_bytes) {
      fail(std::string("the file announces ") + std::to_string(count) + " " + what +
           " but has only " + std::to_string(remaining()) + " bytes left at byte " +
           std::to_string(offset_));
    }
  }
  [[noreturn]] void fail(const std::string& message) const { throw ParseError(file_, 0, message); }

 private:
  std::istream& in_;
  uint64_t size_;
  uint64_t offset_ = 0;
  std::string file_;
};

uint64_t fileSize(const std::string& path) {
  struct stat info;
  if (::stat(path.c_str(), &info) != 0) throw ParseError(path, 0, "cannot open file");
  return static_cast<uint64_t>(info.st_size);
}

std::vector<CalibratedView> sortedByName(std::vector<CalibratedView> views,
                                         const std::string& file) {
  if (views.empty()) throw ParseError(file, 0, "no images");
  std::sort(views.begin(), views.end(),
            [](const CalibratedView& a, const CalibratedView& b) { return a.name < b.name; });
  for (size_t i = 1; i < views.size(); ++i) {
    if (views[i].name == views[i - 1].name) {
      throw ParseError(file, 0, "image '" + views[i].name + "' given twice");
    }
  }
  return views;
}

}  // namespace

std::map<uint32_t, ColmapCamera> parseColmapCamerasBinary(std::istream& in, uint64_t size_bytes,
                                                          const std::string& file) {
  BinaryReader reader(in, size_bytes, file);
  const uint64_t count = reader.read<uint64_t>("the camera count");
  reader.requireFits(count, 4 + 4 + 8 + 8 + 8 * 3, "cameras");
  std::map<uint32_t, ColmapCamera> cameras;
  for (uint64_t i = 0; i < count; ++i) {
    const uint64_t at = reader.offset();
    const uint32_t id = reader.read<uint32_t>("a camera id");
    const int32_t model_id = reader.read<int32_t>("a camera model");
    const uint64_t width = reader.read<uint64_t>("a width");
    const uint64_t height = reader.read<uint64_t>("a height");
    const ModelInfo* model = colmap_detail::modelById(model_id);
    const std::string where = "camera " + std::to_string(id) + " at byte " + std::to_string(at);
    if (model == nullptr)
      reader.fail(where + ": unknown camera model id " + std::to_string(model_id));
    std::vector<double> params(static_cast<size_t>(model->params));
    reader.bytes(params.data(), params.size() * sizeof(double), "camera parameters");
    if (cameras.count(id)) reader.fail(where + ": camera id given twice");
    try {
      cameras[id] = colmap_detail::makeCamera(*model, width, height, params, file, 0,
                                              file + " (" + where + ")");
    } catch (const ParseError& e) {
      reader.fail(where + ": " + std::string(e.what()).substr(file.size() + 2));
    }
  }
  if (cameras.empty()) reader.fail("no cameras");
  if (reader.remaining() != 0)
    reader.fail(std::to_string(reader.remaining()) + " bytes after the last camera");
  return cameras;
}

std::vector<CalibratedView> parseColmapImagesBinary(
    std::istream& in, uint64_t size_bytes, const std::string& file,
    const std::map<uint32_t, ColmapCamera>& cameras) {
  BinaryReader reader(in, size_bytes, file);
  const uint64_t count = reader.read<uint64_t>("the image count");
  reader.requireFits(count, 4 + 8 * 7 + 4 + 1 + 8, "images");
  std::vector<CalibratedView> views;
  for (uint64_t i = 0; i < count; ++i) {
    const uint64_t at = reader.offset();
    const uint32_t id = reader.read<uint32_t>("an image id");
    double q[4], t[3];
    reader.bytes(q, sizeof(q), "a quaternion");
    reader.bytes(t, sizeof(t), "a translation");
    const uint32_t camera_id = reader.read<uint32_t>("a camera id");
    const std::string name = reader.name();
    const uint64_t points = reader.read<uint64_t>("a point count");
    reader.requireFits(points, 24, "points");
    reader.skip(points * 24, "the points");
    const std::string where = "image " + std::to_string(id) + " at byte " + std::to_string(at);
    try {
      views.push_back(colmap_detail::makeView(name, q, t, camera_id, cameras, file, 0,
                                              file + " (" + where + ")"));
    } catch (const ParseError& e) {
      reader.fail(where + ": " + std::string(e.what()).substr(file.size() + 2));
    }
  }
  if (reader.remaining() != 0)
    reader.fail(std::to_string(reader.remaining()) + " bytes after the last image");
  return views;
}

bool isColmapModel(const std::string& directory) {
  return (fileExists(directory + "/cameras.txt") && fileExists(directory + "/images.txt")) ||
         (fileExists(directory + "/cameras.bin") && fileExists(directory + "/images.bin"));
}

std::string colmapModelFormat(const std::string& directory) {
  if (fileExists(directory + "/cameras.txt") && fileExists(directory + "/images.txt")) {
    return "COLMAP text (cameras.txt, images.txt)";
  }
  return "COLMAP binary (cameras.bin, images.bin)";
}

std::vector<CalibratedView> readColmapModel(const std::string& directory) {
  const std::string text_cameras = directory + "/cameras.txt";
  const std::string text_images = directory + "/images.txt";
  if (fileExists(text_cameras) && fileExists(text_images)) {
    return sortedByName(
        colmap_detail::readImagesText(text_images, colmap_detail::readCamerasText(text_cameras)),
        text_images);
  }
  const std::string bin_cameras = directory + "/cameras.bin";
  const std::string bin_images = directory + "/images.bin";
  if (!fileExists(bin_cameras) || !fileExists(bin_images)) {
    throw ParseError(directory, 0,
                     "not a COLMAP sparse model: expected cameras.txt and images.txt, or "
                     "cameras.bin and images.bin");
  }
  std::ifstream camera_stream(bin_cameras, std::ios::binary);
  if (!camera_stream) throw ParseError(bin_cameras, 0, "cannot open file");
  const auto cameras = parseColmapCamerasBinary(camera_stream, fileSize(bin_cameras), bin_cameras);
  std::ifstream image_stream(bin_images, std::ios::binary);
  if (!image_stream) throw ParseError(bin_images, 0, "cannot open file");
  return sortedByName(
      parseColmapImagesBinary(image_stream, fileSize(bin_images), bin_images, cameras), bin_images);
}

}  // namespace sift_hull
