#include "bench_scene.h"

#include "sift_hull/synthetic/scene.h"

namespace sift_hull {
namespace cli {

BenchScene benchScene(int views, int width_px, int height_px, const std::string& support) {
  SceneConfig scene;
  scene.views = views;
  scene.layout = "sphere";
  scene.width_px = width_px;
  scene.height_px = height_px;
  scene.support = support;
  BenchScene bench{Shape::byName(scene.shape), {}, cv::Size(width_px, height_px)};
  bench.cameras = sceneCameras(scene, bench.shape);
  return bench;
}

void addSceneOptions(ArgParser* parser, const std::string& name, const std::string& what, int views,
                     int width_px, int height_px) {
  parser->addOption(name + "-views", "N", "views of the " + what, std::to_string(views));
  parser->addOption(name + "-size", "WxH", "image size of the " + what,
                    std::to_string(width_px) + "x" + std::to_string(height_px));
}

void sceneFromArgs(const ArgParser& parser, const std::string& name, int* views, int* width_px,
                   int* height_px) {
  *views = parser.getInt(name + "-views");
  if (*views < 2) throw UsageError("--" + name + "-views must be at least 2");
  const std::string size = parser.get(name + "-size");
  const cv::Size parsed = parseSizeOption("--" + name + "-size", size);
  if (parsed.width < 8 || parsed.height < 8 || parsed.width > 8192 || parsed.height > 8192) {
    throw UsageError("--" + name + "-size expects WIDTHxHEIGHT, each side in [8, 8192], got '" +
                     size + "'");
  }
  *width_px = parsed.width;
  *height_px = parsed.height;
}

}  // namespace cli
}  // namespace sift_hull
