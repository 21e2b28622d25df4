#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <sstream>

#include "args.h"
#include "bench_timing.h"
#include "commands.h"
#include "sift_hull/synthetic/scene.h"

namespace sift_hull {
namespace cli {
namespace {

/// "K1,K2,P1,P2" or "K1,K2,P1,P2,K3", OpenCV's order.
LensDistortion parseDistortion(const std::string& text) {
  std::vector<double> values;
  std::stringstream in(text);
  std::string field;
  while (std::getline(in, field, ',')) {
    char* end = nullptr;
    const double value = std::strtod(field.c_str(), &end);
    if (field.empty() || end != field.c_str() + field.size() || !std::isfinite(value)) {
      throw UsageError("--distortion expects finite numbers K1,K2,P1,P2[,K3], got '" + text + "'");
    }
    values.push_back(value);
  }
  if (values.size() != 4 && values.size() != 5) {
    throw UsageError("--distortion expects 4 or 5 numbers K1,K2,P1,P2[,K3], got '" + text + "'");
  }
  values.resize(5, 0.0);
  return {values[0], values[1], values[2], values[3], values[4]};
}

std::string joined(const std::vector<std::string>& words) {
  std::string out;
  for (const std::string& word : words) out += (out.empty() ? "" : ", ") + word;
  return out;
}

SceneConfig configFromArgs(const ArgParser& parser) {
  SceneConfig config;
  config.views = parser.getInt("views");
  const cv::Size size = parseSizeOption("--size", parser.get("size"));
  config.width_px = size.width;
  config.height_px = size.height;
  config.shape = parser.get("shape");
  config.layout = parser.get("layout");
  config.seed = static_cast<unsigned>(parser.getInt("seed"));
  config.camera_distance_m = parser.getDouble("camera-distance-m");
  config.background = parser.get("background");
  config.support = parser.get("support");
  config.distortion = parseDistortion(parser.get("distortion"));
  validateOptions(config);
  return config;
}

}  // namespace

int runScene(const std::vector<std::string>& args) {
  const SceneConfig defaults;
  ArgParser parser(
      "scene",
      "Ray-casts a textured object made of analytic primitives, seen by N cameras, and\n"
      "writes images, silhouettes, depth maps (PFM) and the calibration (a Middlebury par\n"
      "file, or a COLMAP model in DIR/sparse for a distorted lens).");
  parser.addOption("out", "DIR", "output directory (created when missing)");
  parser.addOption("views", "N", "number of cameras", std::to_string(defaults.views));
  parser.addOption("size", "WxH", "image size in pixels",
                   std::to_string(defaults.width_px) + "x" + std::to_string(defaults.height_px));
  parser.addOption("shape", "NAME", "one of " + joined(Shape::names()), defaults.shape);
  parser.addOption("layout", "NAME",
                   "camera layout: ring or sphere (with a support: elevations 10 to 70 deg)",
                   defaults.layout);
  parser.addOption("seed", "S", "texture and camera jitter seed", std::to_string(defaults.seed));
  parser.addOption("camera-distance-m", "M", "camera distance from the object's centre in metres",
                   numberText(defaults.camera_distance_m));
  parser.addOption("background", "NAME",
                   "what the rays missing the object see: " + joined(sceneBackgrounds()) +
                       " (blue: uniform dark blue; textured: coloured blobs)",
                   defaults.background);
  parser.addOption("support", "NAME",
                   "what the object stands on: " + joined(sceneSupports()) +
                       " (floor: a tiled plane; turntable: a blue disc on it), lit from above so "
                       "that the object casts a shadow; masks and depth maps stay the object's",
                   defaults.support);
  parser.addOption("distortion", "K1,K2,P1,P2[,K3]",
                   "lens distortion of every camera (OpenCV's radial-tangential model); not zero: "
                   "the calibration is written as a COLMAP model in DIR/sparse",
                   "0,0,0,0");
  parser.addFlag("json", "print the result as one JSON object");
  if (!parser.parse(args)) return 0;
  const SceneConfig config = configFromArgs(parser);
  const std::string out = parser.get("out");

  const auto start = std::chrono::steady_clock::now();
  const std::vector<RenderedView> views = renderScene(config);
  const double render_ms = millisecondsSince(start);
  writeScene(out, config, views);
  const double total_ms = millisecondsSince(start);

  const nlohmann::json result = {
      {"out", out},
      {"views", config.views},
      {"size", {config.width_px, config.height_px}},
      {"shape", config.shape},
      {"background", config.background},
      {"support", config.support},
      {"time_ms", {{"render", render_ms}, {"write", total_ms - render_ms}, {"total", total_ms}}}};
  std::ostringstream text;
  text << "wrote " << config.views << " views of '" << config.shape << "' (" << config.width_px
       << "x" << config.height_px << ") to " << out << "\nrender " << render_ms << " ms, write "
       << total_ms - render_ms << " ms\n";
  printResult(parser.flag("json"), result, text.str());
  return 0;
}

}  // namespace cli
}  // namespace sift_hull
