#include "sift_hull/synthetic/scene.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <limits>
#include <nlohmann/json.hpp>
#include <opencv2/core/utility.hpp>
#include <opencv2/imgcodecs.hpp>
#include <random>
#include <stdexcept>

#include "sift_hull/io/colmap.h"
#include "sift_hull/io/idr.h"
#include "sift_hull/io/nerf.h"
#include "sift_hull/io/pfm.h"
#include "synthetic/support_shading.h"
#include "synthetic/texture.h"

namespace sift_hull {
namespace {

constexpr double kPi = 3.14159265358979323846;

std::string numbered(const char* stem, size_t index, const char* extension) {
  char buffer[64];
  std::snprintf(buffer, sizeof(buffer), "%s_%04zu.%s", stem, index, extension);
  return buffer;
}

/// Unit direction from the target to the camera for view i.
Eigen::Vector3d viewDirection(const SceneConfig& config, int i, std::mt19937* rng) {
  std::uniform_real_distribution<double> jitter(-0.02, 0.02);
  double azimuth, elevation;
  if (config.layout == "ring") {
    azimuth = 2.0 * kPi * i / config.views + jitter(*rng);
    elevation = config.ring_elevation_deg * kPi / 180.0 + jitter(*rng);
  } else if (config.support != "none") {
    // Fibonacci points over the band of elevations 10 to 70 deg, even in area: the floor hides
    // what lies below, and looking straight down shows little but the top.
    const double low = std::sin(10.0 * kPi / 180.0), high = std::sin(70.0 * kPi / 180.0);
    elevation = std::asin(low + (high - low) * (i + 0.5) / config.views);
    azimuth = i * kPi * (3.0 - std::sqrt(5.0)) + jitter(*rng);
  } else {  // Fibonacci sphere, poles left out so that "up" stays defined
    const double height = 1.0 - 2.0 * (i + 0.5) / config.views;
    elevation = std::asin(height) * 0.85;
    azimuth = i * kPi * (3.0 - std::sqrt(5.0)) + jitter(*rng);
  }
  return {std::cos(elevation) * std::cos(azimuth), std::cos(elevation) * std::sin(azimuth),
          std::sin(elevation)};
}

/// Rotation (rows: camera x right, y down, z forward) of a camera looking from `centre` at
/// `target`.
Eigen::Matrix3d lookAt(const Eigen::Vector3d& centre, const Eigen::Vector3d& target) {
  const Eigen::Vector3d z = (target - centre).normalized();
  const Eigen::Vector3d x = z.cross(Eigen::Vector3d::UnitZ()).normalized();
  const Eigen::Vector3d y = z.cross(x);
  Eigen::Matrix3d R;
  R << x.transpose(), y.transpose(), z.transpose();
  return R;
}

Eigen::Matrix3d intrinsics(const SceneConfig& config, const Shape& shape) {
  const double half_angle = std::asin(shape.boundingRadius() / config.camera_distance_m);
  const double focal_px = 0.5 * config.fill_fraction * std::min(config.width_px, config.height_px) /
                          std::tan(half_angle);
  Eigen::Matrix3d K;
  K << focal_px, 0.0, 0.5 * (config.width_px - 1), 0.0, focal_px, 0.5 * (config.height_px - 1), 0.0,
      0.0, 1.0;
  return K;
}

/// The colour of a ray that misses the object (SceneConfig::background, checked by validate).
cv::Vec3b backgroundColour(const std::string& background, const Eigen::Vector3d& direction_W,
                           unsigned seed) {
  if (background == "blue") return cv::Vec3b(120, 50, 25);  // BGR, grey 0.196
  if (background == "textured") {
    // Blobs of the solid texture on a sphere far away, in saturated mid-bright colours; another
    // seed than the object's, so the two do not share a pattern.
    const cv::Vec3f albedo = solidTexture(8.0 * direction_W, seed + 7919);
    cv::Vec3b colour;
    for (int c = 0; c < 3; ++c) colour[c] = cv::saturate_cast<uint8_t>(40.0 + 180.0 * albedo[c]);
    return colour;
  }
  return cv::Vec3b(0, 0, 0);
}

/// What every pixel of a view shares.
struct ViewLighting {
  const Shape& shape;
  const SceneSupport& support;
  const std::string& background;
  unsigned seed;
  double pixel_angle_rad;  ///< the angle a pixel spans, for the floor's level of detail
};

void shadePixel(const ViewLighting& scene, const PinholeCamera& camera,
                const Eigen::Vector2d& pixel, cv::Vec3b* colour, uint8_t* inside, float* depth) {
  static const Eigen::Vector3d fixed_light_W = Eigen::Vector3d(0.4, 0.3, 0.85).normalized();
  const Eigen::Vector3d origin = camera.centre();
  const Eigen::Vector3d direction = camera.rayDirection(pixel);
  RayHit hit;
  if (!direction.allFinite() || !scene.shape.firstHit(origin, direction, &hit)) {
    // The object stands on the support, the cameras above it: a ray that meets the object meets
    // it first, so the support never changes the mask.
    SupportHit support_hit;
    if (direction.allFinite() && firstSupportHit(scene.support, origin, direction, &support_hit)) {
      *colour = shadeSupport(scene.shape, scene.support, support_hit, origin, direction,
                             scene.pixel_angle_rad, scene.seed);
    } else {
      *colour = backgroundColour(scene.background, direction, scene.seed);
    }
    *inside = 0;
    *depth = std::numeric_limits<float>::infinity();
    return;
  }
  const Eigen::Vector3d X_W = origin + hit.distance_m * direction;
  const Eigen::Vector3d& light_W = scene.support.floor ? scene.support.light_W : fixed_light_W;
  const double shading =
      kAmbientShading + (1.0 - kAmbientShading) * std::max(0.0, hit.normal_W.dot(light_W));
  const cv::Vec3f albedo = solidTexture(X_W, scene.seed);
  for (int c = 0; c < 3; ++c)
    (*colour)[c] = cv::saturate_cast<uint8_t>(255.0 * shading * albedo[c]);
  *inside = 255;
  *depth = static_cast<float>(camera.depth(X_W));
}

void makeDirectory(const std::string& directory) {
  std::error_code error;
  std::filesystem::create_directories(directory, error);
  if (error) throw std::runtime_error(directory + ": cannot create directory: " + error.message());
}

void writeImage(const std::string& path, const cv::Mat& image) {
  if (!cv::imwrite(path, image)) throw std::runtime_error(path + ": cannot write image");
}

nlohmann::json toJson(const SceneConfig& c) {
  return {{"views", c.views},
          {"width_px", c.width_px},
          {"height_px", c.height_px},
          {"shape", c.shape},
          {"layout", c.layout},
          {"seed", c.seed},
          {"camera_distance_m", c.camera_distance_m},
          {"ring_elevation_deg", c.ring_elevation_deg},
          {"fill_fraction", c.fill_fraction},
          {"background", c.background},
          {"support", c.support},
          {"distortion",
           {c.distortion.k1, c.distortion.k2, c.distortion.p1, c.distortion.p2, c.distortion.k3}}};
}

SceneConfig configFromJson(const nlohmann::json& j) {
  SceneConfig c;
  c.views = j.at("views").get<int>();
  c.width_px = j.at("width_px").get<int>();
  c.height_px = j.at("height_px").get<int>();
  c.shape = j.at("shape").get<std::string>();
  c.layout = j.at("layout").get<std::string>();
  c.seed = j.at("seed").get<unsigned>();
  c.camera_distance_m = j.at("camera_distance_m").get<double>();
  c.ring_elevation_deg = j.at("ring_elevation_deg").get<double>();
  c.fill_fraction = j.at("fill_fraction").get<double>();
  c.background = j.value("background", "black");  // scenes written before it existed: black
  c.support = j.value("support", "none");
  if (j.contains("distortion")) {
    const std::vector<double> d = j.at("distortion").get<std::vector<double>>();
    if (d.size() != 5) throw std::invalid_argument("distortion must hold k1, k2, p1, p2, k3");
    c.distortion = {d[0], d[1], d[2], d[3], d[4]};
  }
  return c;
}

}  // namespace

std::string depthFileName(const std::string& view_name) {
  const size_t dot = view_name.find_last_of('.');
  return view_name.substr(0, dot) + ".pfm";
}

void validate(const SceneConfig& config) {
  const auto require = [](bool ok, const std::string& message) {
    if (!ok) throw std::invalid_argument(message);
  };
  require(config.views >= 1 && config.views <= 1000, "views must be between 1 and 1000");
  require(config.width_px >= 8 && config.height_px >= 8 && config.width_px <= 8192 &&
              config.height_px <= 8192,
          "image size must be between 8x8 and 8192x8192");
  const double radius = Shape::byName(config.shape).boundingRadius();  // throws on an unknown name
  require(config.layout == "ring" || config.layout == "sphere", "layout must be ring or sphere");
  require(config.camera_distance_m > 1.05 * radius,
          "camera distance must exceed the shape's bounding radius");
  require(std::abs(config.ring_elevation_deg) < 85.0, "ring elevation must lie in (-85, 85) deg");
  require(config.fill_fraction > 0.0 && config.fill_fraction <= 1.0,
          "fill fraction must lie in (0, 1]");
  const std::vector<std::string>& backgrounds = sceneBackgrounds();
  require(std::find(backgrounds.begin(), backgrounds.end(), config.background) != backgrounds.end(),
          "background must be black, blue or textured, not '" + config.background + "'");
  const std::vector<std::string>& supports = sceneSupports();
  require(std::find(supports.begin(), supports.end(), config.support) != supports.end(),
          "support must be none, floor or turntable, not '" + config.support + "'");
  require(config.support == "none" || config.layout != "ring" || config.ring_elevation_deg >= 5.0,
          "with a support the ring elevation must be at least 5 deg (cameras above the floor)");
  validate(config.distortion);
  const PinholeCamera camera = PinholeCamera(intrinsics(config, Shape::byName(config.shape)),
                                             Eigen::Matrix3d::Identity(), Eigen::Vector3d::Zero())
                                   .withDistortion(config.distortion);
  require(camera.distortionInvertibleOver(
              Eigen::Vector2d(-0.5, -0.5),
              Eigen::Vector2d(config.width_px - 0.5, config.height_px - 0.5)),
          "distortion folds over within the image (no one-to-one undistortion)");
}

std::vector<CalibratedView> sceneCameras(const SceneConfig& config, const Shape& shape) {
  validate(config);
  std::mt19937 rng(config.seed);
  const Eigen::Matrix3d K = intrinsics(config, shape);
  std::vector<CalibratedView> views;
  for (int i = 0; i < config.views; ++i) {
    const Eigen::Vector3d target = shape.boundingCentre();
    const Eigen::Vector3d centre =
        target + config.camera_distance_m * viewDirection(config, i, &rng);
    CalibratedView view;
    view.name = numbered("view", i, "png");
    view.camera = PinholeCamera::fromCentre(K, lookAt(centre, target), centre)
                      .withDistortion(config.distortion);
    views.push_back(view);
  }
  return views;
}

const std::vector<std::string>& sceneBackgrounds() {
  static const std::vector<std::string> names = {"black", "blue", "textured"};
  return names;
}

RenderedView renderView(const Shape& shape, const CalibratedView& view, cv::Size size,
                        unsigned seed, const std::string& background, const std::string& support) {
  RenderedView out{view, cv::Mat(size, CV_8UC3), cv::Mat(size, CV_8UC1), cv::Mat(size, CV_32FC1)};
  const SceneSupport scene_support = sceneSupport(shape, support);
  const ViewLighting scene{shape, scene_support, background, seed, 1.0 / view.camera.K()(0, 0)};
  cv::parallel_for_(cv::Range(0, size.height), [&](const cv::Range& rows) {
    for (int v = rows.start; v < rows.end; ++v) {
      for (int u = 0; u < size.width; ++u) {
        shadePixel(scene, view.camera, Eigen::Vector2d(u, v), &out.image.at<cv::Vec3b>(v, u),
                   &out.mask.at<uint8_t>(v, u), &out.depth.at<float>(v, u));
      }
    }
  });
  return out;
}

std::vector<RenderedView> renderScene(const SceneConfig& config) {
  const Shape shape = Shape::byName(config.shape);
  std::vector<RenderedView> rendered;
  for (const CalibratedView& view : sceneCameras(config, shape)) {
    rendered.push_back(renderView(shape, view, cv::Size(config.width_px, config.height_px),
                                  config.seed, config.background, config.support));
  }
  return rendered;
}

RenderedView renderSceneView(const SceneConfig& config, size_t index) {
  const Shape shape = Shape::byName(config.shape);
  const std::vector<CalibratedView> cameras = sceneCameras(config, shape);
  if (index >= cameras.size()) throw std::out_of_range("renderSceneView: no such view");
  return renderView(shape, cameras[index], cv::Size(config.width_px, config.height_px), config.seed,
                    config.background, config.support);
}

void writeScene(const std::string& directory, const SceneConfig& config,
                const std::vector<RenderedView>& views) {
  makeDirectory(directory);
  makeDirectory(directory + "/" + kMaskDirectory);
  makeDirectory(directory + "/" + kDepthDirectory);
  std::vector<CalibratedView> cameras;
  for (const RenderedView& view : views) cameras.push_back(view.view);
  if (config.distortion.isZero()) {
    writeMiddleburyPar(directory + "/scene_par.txt", cameras);
  } else {
    writeColmapText(directory + "/sparse", cameras, config.width_px, config.height_px);
  }
  // The same cameras in the formats of today's photo sets: NeRF's transforms.json and, without
  // distortion, IDR's cameras.npz with the shape's bounding sphere as scale_mat.
  const LensDistortion& lens = config.distortion;
  if (!lens.fisheye && !lens.rational() && lens.k3 == 0.0) {
    writeNerfTransforms(directory + "/transforms.json", cameras, config.width_px, config.height_px);
  }
  if (lens.isZero()) {
    const Shape shape = Shape::byName(config.shape);
    Eigen::Matrix4d scale_mat = Eigen::Matrix4d::Identity();
    scale_mat.topLeftCorner<3, 3>() *= shape.boundingRadius();
    scale_mat.topRightCorner<3, 1>() = shape.boundingCentre();
    writeIdrCameras(directory + "/cameras.npz", cameras, scale_mat);
  }
  const std::string json_path = directory + "/scene.json";
  std::ofstream json_file(json_path);
  json_file << toJson(config).dump(2) << '\n';
  if (!json_file) throw std::runtime_error(json_path + ": cannot write file");
  cv::parallel_for_(cv::Range(0, static_cast<int>(views.size())), [&](const cv::Range& range) {
    for (int i = range.start; i < range.end; ++i) {
      const std::string& name = views[i].view.name;
      writeImage(directory + "/" + name, views[i].image);
      writeImage(directory + "/" + kMaskDirectory + "/" + name, views[i].mask);
      writePfm(directory + "/" + kDepthDirectory + "/" + depthFileName(name), views[i].depth);
    }
  });
}

std::string sceneCalibration(const std::string& directory) {
  const std::string par = directory + "/scene_par.txt", sparse = directory + "/sparse";
  return !std::filesystem::exists(par) && std::filesystem::exists(sparse) ? sparse : par;
}

SceneData readScene(const std::string& directory) {
  const std::string json_path = directory + "/scene.json";
  std::ifstream json_file(json_path);
  if (!json_file) throw std::runtime_error(json_path + ": missing; not a scene directory");
  SceneData scene;
  try {
    scene.config = configFromJson(nlohmann::json::parse(json_file));
  } catch (const nlohmann::json::exception& e) {
    throw ParseError(json_path, 0, e.what());
  }
  scene.views = readCalibration(sceneCalibration(directory));
  for (const CalibratedView& view : scene.views) {
    scene.depths.push_back(
        readPfm(directory + "/" + kDepthDirectory + "/" + depthFileName(view.name)));
  }
  return scene;
}

HullInput hullInputOf(const std::vector<RenderedView>& views) {
  HullInput input;
  for (const RenderedView& view : views) {
    input.names.push_back(view.view.name);
    input.cameras.push_back(view.view.camera);
    input.masks.push_back(view.mask);
  }
  return input;
}

}  // namespace sift_hull
