// IDR / NeuS / VolSDF camera files, cameras.npz and cameras_sphere.npz (sift_hull/io/idr.h).

#include "sift_hull/io/idr.h"

#include <sys/stat.h>

#include <Eigen/Dense>
#include <cctype>
#include <cmath>
#include <optional>
#include <set>
#include <sstream>
#include <stdexcept>

#include "sift_hull/io/llff.h"
#include "sift_hull/io/nerf.h"
#include "sift_hull/io/npz.h"
#include "sift_hull/io/view_orientation.h"
#include "sift_hull/limits.h"

namespace sift_hull {
namespace {

[[noreturn]] void fail(const std::string& file, const std::string& message) {
  throw ParseError(file, 0, message);
}

bool isFile(const std::string& path) {
  struct stat info;
  return ::stat(path.c_str(), &info) == 0 && S_ISREG(info.st_mode);
}

bool isDirectory(const std::string& path) {
  struct stat info;
  return ::stat(path.c_str(), &info) == 0 && S_ISDIR(info.st_mode);
}

std::string worldMatName(uint64_t index) { return "world_mat_" + std::to_string(index) + ".npy"; }

/// The index of a "world_mat_I.npy" entry; empty for any other name (world_mat_inv_I.npy, ...).
/// Throws for an index with a leading zero or beyond the view limit.
std::optional<uint64_t> worldMatIndex(const std::string& name, const std::string& path) {
  const std::string prefix = "world_mat_", suffix = ".npy";
  if (name.size() <= prefix.size() + suffix.size() || name.compare(0, prefix.size(), prefix) != 0 ||
      name.compare(name.size() - suffix.size(), suffix.size(), suffix) != 0) {
    return std::nullopt;
  }
  const std::string digits =
      name.substr(prefix.size(), name.size() - prefix.size() - suffix.size());
  for (const char c : digits) {
    if (!std::isdigit(static_cast<unsigned char>(c))) return std::nullopt;
  }
  if (digits.size() > 1 && digits[0] == '0') {
    fail(path, name + ": the index has a leading zero (world_mat_0.npy, world_mat_1.npy, ...)");
  }
  if (digits.size() > 9 || std::stoull(digits) >= limits::kMaxCalibrationViews) {
    fail(path, name + ": the index is beyond the limit of " +
                   std::to_string(limits::kMaxCalibrationViews) + " views");
  }
  return std::stoull(digits);
}

/// A 4x4 entry whose last row is 0 0 0 1, every value finite.
Eigen::Matrix4d readMatrix(const NpzReader& npz, const std::string& name) {
  const std::string bytes = npz.read(name, limits::kMaxNpzEntryBytes);
  std::istringstream in(bytes);
  NpyMatrix matrix;
  try {
    matrix = parseNpyMatrix(in, bytes.size(), name, 4, 4, true);
  } catch (const ParseError& e) {
    fail(npz.path(), e.what());
  }
  Eigen::Matrix4d m;
  for (int r = 0; r < 4; ++r) {
    for (int c = 0; c < 4; ++c) m(r, c) = matrix.at(r, c);
  }
  if (!m.allFinite()) fail(npz.path(), name + ": a value is not finite");
  if ((m.row(3) - Eigen::RowVector4d(0, 0, 0, 1)).cwiseAbs().maxCoeff() > 1e-6) {
    std::ostringstream row;
    row << m.row(3);
    fail(npz.path(), name + ": the last row is " + row.str() + ", not 0 0 0 1");
  }
  return m;
}

/// Names of views for an error message: 'a.png', 'b.png', ...
std::string nameList(const std::vector<CalibratedView>& views, const std::vector<size_t>& odd) {
  std::string list;
  for (size_t i = 0; i < odd.size() && i < 10; ++i) {
    list += (i ? ", '" : "'") + views[odd[i]].name + "'";
  }
  if (odd.size() > 10) list += " and " + std::to_string(odd.size() - 10) + " more";
  return list;
}

/// Orients every view by the depth of the object's centre; all must agree on the handedness.
void orientByObject(std::vector<CalibratedView>* views, const Eigen::Vector3d& centre,
                    const std::string& path) {
  std::vector<size_t> proper, improper;
  for (size_t i = 0; i < views->size(); ++i) {
    CalibratedView& view = (*views)[i];
    const double depth = view.camera.depth(centre);
    if (!(std::abs(depth) > 0.0)) {
      fail(path, worldMatName(i) + " (" + view.name +
                     "): scale_mat_0's centre, the object, lies in the camera's focal plane");
    }
    if (depth < 0.0) view.camera = view.camera.negated();
    (view.camera.improper() ? improper : proper).push_back(i);
  }
  if (proper.empty() || improper.empty()) return;
  const bool few_improper = improper.size() <= proper.size();
  fail(path, "the cameras cannot be oriented consistently: " +
                 nameList(*views, few_improper ? improper : proper) +
                 " see the object (scale_mat_0's centre) in front of them only if their world "
                 "frame is " +
                 (few_improper ? "mirrored" : "right-handed") + " while the other cameras' is " +
                 (few_improper ? "right-handed" : "mirrored") + "; check their world_mat");
}

}  // namespace

namespace {

IdrCameras readMatrices(const NpzReader& npz) {
  const std::string& npz_path = npz.path();
  std::set<uint64_t> indices;
  for (const std::string& name : npz.names()) {
    if (const std::optional<uint64_t> index = worldMatIndex(name, npz_path)) indices.insert(*index);
  }
  if (indices.empty()) {
    fail(npz_path, "no world_mat_0.npy entry: not an IDR / NeuS cameras file");
  }
  uint64_t expected = 0;
  for (const uint64_t index : indices) {
    if (index != expected) {
      fail(npz_path, "no " + worldMatName(expected) + ", though " +
                         worldMatName(*indices.rbegin()) +
                         " is given: the indices must run from 0 without a gap");
    }
    ++expected;
  }
  IdrCameras cameras;
  cameras.world_mats.reserve(indices.size());
  for (uint64_t i = 0; i < indices.size(); ++i) {
    cameras.world_mats.push_back(readMatrix(npz, worldMatName(i)));
  }
  if (npz.has("scale_mat_0.npy")) {
    const Eigen::Matrix4d S = readMatrix(npz, "scale_mat_0.npy");
    const Eigen::Matrix3d block = S.topLeftCorner<3, 3>();
    if (!(std::abs(block.determinant()) > 1e-12 * std::pow(block.cwiseAbs().maxCoeff(), 3))) {
      fail(npz_path, "scale_mat_0.npy: the upper left 3x3 block is singular");
    }
    cameras.scale_mat = S;
  }
  return cameras;
}

}  // namespace

IdrCameras readIdrCameraMatrices(const std::string& npz_path) {
  if (!isFile(npz_path)) fail(npz_path, "cannot open file");
  return readMatrices(NpzReader(npz_path, limits::kMaxNpzEntries));
}

IdrCameras parseIdrCameraMatrices(const std::string& bytes, const std::string& name) {
  return readMatrices(NpzReader(name, bytes, limits::kMaxNpzEntries));
}

std::vector<CalibratedView> idrViews(const IdrCameras& cameras,
                                     const std::vector<std::string>& image_names,
                                     const std::string& npz_path) {
  if (image_names.size() != cameras.world_mats.size()) {
    fail(npz_path, "holds " + std::to_string(cameras.world_mats.size()) +
                       " cameras (world_mat_0 to world_mat_" +
                       std::to_string(cameras.world_mats.size() - 1) + ") but there are " +
                       std::to_string(image_names.size()) + " images");
  }
  std::vector<CalibratedView> views;
  views.reserve(image_names.size());
  for (size_t i = 0; i < image_names.size(); ++i) {
    const std::string where = worldMatName(i) + " (" + image_names[i] + ")";
    CalibratedView view;
    view.name = image_names[i];
    view.source = npz_path + " (" + where + ")";
    view.camera_model = "IDR";
    try {
      view.camera = PinholeCamera::fromProjection(cameras.world_mats[i].topRows<3>());
    } catch (const std::invalid_argument& e) {
      fail(npz_path, where + ": " + e.what());
    }
    views.push_back(view);
  }
  if (cameras.scale_mat) {
    orientByObject(&views, cameras.scale_mat->topRightCorner<3, 1>(), npz_path);
  } else {
    orientViews(&views, npz_path);
  }
  return views;
}

std::string idrImageDirectory(const std::string& npz_path, const std::string& image_directory) {
  return image_directory.empty() ? parentDirectory(npz_path) + "/image" : image_directory;
}

std::vector<CalibratedView> readIdrCameras(const std::string& npz_path,
                                           const std::string& image_directory) {
  const IdrCameras cameras = readIdrCameraMatrices(npz_path);
  const std::string directory = idrImageDirectory(npz_path, image_directory);
  std::vector<std::string> names;
  try {
    names = listImageFiles(directory);
  } catch (const std::runtime_error& e) {
    fail(npz_path, std::string("the views are the images of ") + e.what());
  }
  if (names.size() != cameras.world_mats.size()) {
    fail(npz_path, "holds " + std::to_string(cameras.world_mats.size()) +
                       " cameras but there are " + std::to_string(names.size()) + " images in " +
                       directory + " (view I is the I-th image by name)");
  }
  return idrViews(cameras, names, npz_path);
}

std::string idrCamerasFile(const std::string& path) {
  if (!isDirectory(path)) {
    const std::string suffix = ".npz";
    std::string end = path.size() >= suffix.size() ? path.substr(path.size() - 4) : "";
    for (char& c : end) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
    return end == suffix ? path : "";
  }
  for (const char* other : {"cameras.bin", "cameras.txt"}) {
    if (isFile(path + "/" + other)) return "";
  }
  if (!nerfTransformFiles(path).empty()) return "";
  for (const char* name : {"cameras.npz", "cameras_sphere.npz"}) {
    if (isFile(path + "/" + name)) return path + "/" + name;
  }
  return "";
}

std::optional<Box3d> idrObjectBox(const IdrCameras& cameras) {
  if (!cameras.scale_mat) return std::nullopt;
  const Eigen::Matrix4d& S = *cameras.scale_mat;
  // The unit sphere's image S x reaches, along axis r, as far as row r of S's 3x3 block is long.
  const Eigen::Vector3d half = S.topLeftCorner<3, 3>().rowwise().norm();
  Box3d box;
  box.min_W = S.topRightCorner<3, 1>() - half;
  box.max_W = S.topRightCorner<3, 1>() + half;
  return box;
}

std::optional<Box3d> idrObjectBox(const std::string& path) {
  const std::string file = idrCamerasFile(path);
  if (file.empty()) return std::nullopt;
  return idrObjectBox(readIdrCameraMatrices(file));
}

void writeIdrCameras(const std::string& path, const std::vector<CalibratedView>& views,
                     const Eigen::Matrix4d& scale_mat) {
  std::vector<std::pair<std::string, std::string>> entries;
  for (size_t i = 0; i < views.size(); ++i) {
    const PinholeCamera& camera = views[i].camera;
    if (camera.distorted()) {
      throw std::runtime_error(path + ": view '" + views[i].name + "' has lens distortion (" +
                               describeDistortion(camera.distortion()) +
                               "), which an IDR cameras.npz cannot hold");
    }
    Eigen::Matrix4d world_mat = Eigen::Matrix4d::Identity();
    world_mat.topRows<3>() = camera.projectionMatrix();
    entries.emplace_back(worldMatName(i), npyBytes(world_mat));
    entries.emplace_back("scale_mat_" + std::to_string(i) + ".npy", npyBytes(scale_mat));
  }
  writeNpz(path, entries);
}

}  // namespace sift_hull
