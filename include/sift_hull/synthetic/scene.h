#pragma once

#include <opencv2/core.hpp>
#include <string>
#include <vector>

#include "sift_hull/hull/hull_pipeline.h"
#include "sift_hull/io/calibration.h"
#include "sift_hull/synthetic/scene_support.h"
#include "sift_hull/synthetic/shape.h"

namespace sift_hull {

/// A synthetic scene: a textured shape at the world origin seen by cameras around it.
struct SceneConfig {
  int views = 16;
  int width_px = 640;
  int height_px = 480;
  std::string shape = Shape::defaultName();
  /// "ring" (one elevation, ring_elevation_deg) or "sphere" (spread over the sphere, elevations
  /// within +-76.5 deg; with a support, over its upper part only: elevations 10 to 70 deg).
  std::string layout = "ring";
  unsigned seed = 1;                 ///< texture and camera jitter
  double camera_distance_m = 4.0;    ///< from the shape's bounding centre
  double ring_elevation_deg = 25.0;  ///< above the horizontal plane, for the ring layout (>= 5
                                     ///< with a support, so the cameras stay above the floor)
  double fill_fraction = 0.8;        ///< share of the smaller image side the bounding sphere spans
  /// What the rays that miss the object see (sceneBackgrounds()): "black"; "blue", a uniform dark
  /// blue (grey level 0.196, just above the Middlebury recipe's threshold); "textured", coloured
  /// blobs on a sphere at infinity (a colour per ray direction, so the views see one world).
  std::string background = "black";
  /// What the object stands on (sceneSupports(), SceneSupport): "none" (it floats, lit by a fixed
  /// light without shadows); "floor", an infinite plane of mottled grey-brown tiles touching the
  /// shape's lowest point; "turntable", a saturated blue disc (radius 1.6 times the shape's
  /// bounding radius, 0.05 times it thick) on that floor, the object standing on the disc's centre.
  /// With a support, one light from above at 40 degrees from the vertical lights the object and the
  /// support, and the object casts its shadow onto the floor and the disc. The rays that miss the
  /// object and the support (above the horizon) see the background. The masks and the depth maps
  /// stay those of the object alone.
  std::string support = "none";
  /// Lens distortion of every camera. Not zero: the images, masks and depth maps are those of the
  /// distorted lens (each pixel's ray undistorted), and writeScene writes the calibration as a
  /// COLMAP text model (sparse/), as a par file cannot hold distortion.
  LensDistortion distortion;
};

/// The background names SceneConfig::background takes.
const std::vector<std::string>& sceneBackgrounds();

/// Throws std::invalid_argument naming the first bad field; a distortion must be one-to-one over
/// the image (PinholeCamera::distortionInvertibleOver).
void validate(const SceneConfig& config);

/// One rendered view. Pixel (u, v) is the colour seen along the ray through its centre.
struct RenderedView {
  CalibratedView view;
  cv::Mat image;  ///< CV_8UC3, BGR, on the scene's support and background
  cv::Mat mask;   ///< CV_8UC1, 255 where the ray hits the object (never the support or a shadow)
  /// CV_32FC1, depth of the object along the optical axis in metres; +inf wherever the ray misses
  /// the object, on the support as on the background.
  cv::Mat depth;
};

/// The cameras of a scene, looking at the shape's bounding centre, named view_NNNN.png.
std::vector<CalibratedView> sceneCameras(const SceneConfig& config, const Shape& shape);

/// Ray-casts one view: solid procedural texture, Lambertian shading under a fixed world light.
/// `background` and `support` as SceneConfig::background and SceneConfig::support. The mask and
/// the depth map are the object's whatever the support: the support never hides the object from a
/// camera above the floor (sceneCameras places them there with a support); a camera below it sees
/// the object through the floor.
RenderedView renderView(const Shape& shape, const CalibratedView& view, cv::Size size,
                        unsigned seed, const std::string& background = "black",
                        const std::string& support = "none");

std::vector<RenderedView> renderScene(const SceneConfig& config);

/// One view of a scene (index into sceneCameras), rendered alone.
RenderedView renderSceneView(const SceneConfig& config, size_t index);

/// Sub-directories of a scene directory holding, under each view's name, its mask (PNG) and its
/// depth map (the name with the extension .pfm).
inline constexpr const char* kMaskDirectory = "masks";
inline constexpr const char* kDepthDirectory = "depth";

/// Writes into `directory` (created when missing) the images view_NNNN.png, masks/view_NNNN.png,
/// depth/view_NNNN.pfm, scene.json (the config) and the calibration: scene_par.txt (Middlebury
/// format), or for a distorted lens sparse/cameras.txt and sparse/images.txt (COLMAP text); and the
/// same cameras as transforms.json (NeRF; not for fisheye, rational or k3 lenses) and cameras.npz
/// (IDR, scale_mat the shape's bounding sphere; without distortion).
void writeScene(const std::string& directory, const SceneConfig& config,
                const std::vector<RenderedView>& views);

/// The calibration a scene directory holds, to give readCalibration or `--calib`:
/// DIR/scene_par.txt, or DIR/sparse when only that exists.
std::string sceneCalibration(const std::string& directory);

/// What a scene directory holds, read back: cameras, depth maps and the config that made it.
struct SceneData {
  SceneConfig config;
  std::vector<CalibratedView> views;
  std::vector<cv::Mat> depths;  ///< CV_32FC1 per view, as in RenderedView
};

/// Throws ParseError / std::runtime_error naming the file at fault.
SceneData readScene(const std::string& directory);

/// Throws std::runtime_error naming the scene directory, `views_source` (where the views were
/// read from) and the first view at fault when the views are not views of the scene: a name the
/// scene does not hold, a camera that sees the scene's solid (its bounding sphere) more than 1 %
/// of the image diagonal (at least 2 px) from where the scene's camera of that name does, or a
/// silhouette whose intersection over union with the scene's mask is below 0.5 (when the input
/// holds silhouettes: without, the names and cameras are compared). A ground truth
/// of another scene would otherwise score the views against the wrong solid.
void requireViewsOfScene(const SceneData& scene, const std::string& scene_directory,
                         const HullInput& input, const std::string& views_source);

/// "view_0003.png" -> "view_0003.pfm".
std::string depthFileName(const std::string& view_name);

/// The names, cameras and masks of rendered views.
HullInput hullInputOf(const std::vector<RenderedView>& views);

}  // namespace sift_hull
