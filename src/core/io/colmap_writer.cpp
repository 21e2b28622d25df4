#include <Eigen/Geometry>
#include <filesystem>
#include <fstream>
#include <iomanip>
#include <stdexcept>

#include "sift_hull/io/colmap.h"

namespace sift_hull {
namespace {

std::ofstream openForWriting(const std::string& path) {
  std::ofstream out(path);
  if (!out) throw std::runtime_error(path + ": cannot write file");
  out << std::setprecision(17);
  return out;
}

void checkWritable(const std::string& directory, const CalibratedView& view) {
  const PinholeCamera& camera = view.camera;
  if (camera.improper()) {
    throw std::runtime_error(directory + ": view '" + view.name +
                             "' has a mirrored world frame (det R = -1), which COLMAP cannot hold");
  }
  if (camera.K()(0, 1) != 0.0) {
    throw std::runtime_error(directory + ": view '" + view.name +
                             "' has a skewed K, which COLMAP cannot hold");
  }
}

void writeCamera(std::ofstream& out, size_t id, const PinholeCamera& camera, int width_px,
                 int height_px) {
  const Eigen::Matrix3d& K = camera.K();
  const LensDistortion& d = camera.distortion();
  const bool full = d.k3 != 0.0 || d.rational();
  const char* model = !camera.distorted() ? "PINHOLE"
                      : d.fisheye         ? "OPENCV_FISHEYE"
                      : full              ? "FULL_OPENCV"
                                          : "OPENCV";
  out << id << ' ' << model << ' ' << width_px << ' ' << height_px << ' ' << K(0, 0) << ' '
      << K(1, 1) << ' ' << K(0, 2) + 0.5 << ' ' << K(1, 2) + 0.5;
  if (d.fisheye) {
    out << ' ' << d.k1 << ' ' << d.k2 << ' ' << d.k3 << ' ' << d.k4 << '\n';
    return;
  }
  if (camera.distorted()) out << ' ' << d.k1 << ' ' << d.k2 << ' ' << d.p1 << ' ' << d.p2;
  if (camera.distorted() && full) {
    out << ' ' << d.k3 << ' ' << d.k4 << ' ' << d.k5 << ' ' << d.k6;
  }
  out << '\n';
}

}  // namespace

void writeColmapText(const std::string& directory, const std::vector<CalibratedView>& views,
                     int width_px, int height_px) {
  std::error_code error;
  std::filesystem::create_directories(directory, error);
  if (error) throw std::runtime_error(directory + ": cannot create directory: " + error.message());
  for (const CalibratedView& view : views) checkWritable(directory, view);
  std::ofstream cameras = openForWriting(directory + "/cameras.txt");
  std::ofstream images = openForWriting(directory + "/images.txt");
  cameras << "# CAMERA_ID, MODEL, WIDTH, HEIGHT, PARAMS[]\n";
  images << "# IMAGE_ID, QW, QX, QY, QZ, TX, TY, TZ, CAMERA_ID, NAME\n# POINTS2D[] as (X, Y, "
            "POINT3D_ID)\n";
  for (size_t i = 0; i < views.size(); ++i) {
    const PinholeCamera& camera = views[i].camera;
    writeCamera(cameras, i + 1, camera, width_px, height_px);
    const Eigen::Quaterniond q(camera.R());
    const Eigen::Vector3d& t = camera.t();
    images << i + 1 << ' ' << q.w() << ' ' << q.x() << ' ' << q.y() << ' ' << q.z() << ' ' << t.x()
           << ' ' << t.y() << ' ' << t.z() << ' ' << i + 1 << ' ' << views[i].name << "\n\n";
  }
  if (!cameras || !images) throw std::runtime_error(directory + ": cannot write the COLMAP model");
}

}  // namespace sift_hull
