// The concave synthetic scenes of the refinement tests: 20 views on a sphere at 320x240, their
// silhouettes' hull, and exact surface points from the renderer's depth maps.
#pragma once

#include <cmath>
#include <string>
#include <vector>

#include "sift_hull/hull/hull_config.h"
#include "sift_hull/hull/hull_pipeline.h"
#include "sift_hull/refine/surface_points.h"
#include "sift_hull/synthetic/scene.h"
#include "sift_hull/synthetic/shape.h"

namespace sift_hull {

struct ConcaveScene {
  ConcaveScene(const std::string& name, int max_depth)
      : views(renderScene(config(name))),
        shape(Shape::byName(name)),
        hull(buildHull(hullInputOf(views), depth(max_depth))) {}

  static SceneConfig config(const std::string& name) {
    SceneConfig config;
    config.shape = name;
    config.views = 20;
    config.layout = "sphere";
    config.width_px = 320;
    config.height_px = 240;
    return config;
  }
  static HullConfig depth(int max_depth) {
    HullConfig config;
    config.max_depth = max_depth;
    return config;
  }

  std::vector<RenderedView> views;
  Shape shape;
  HullResult hull;
};

/// Every `step`-th pixel of each view on the object, at its rendered depth: exact surface points
/// seen by that view only.
inline std::vector<SurfacePoint> depthMapPoints(const std::vector<RenderedView>& views, int step) {
  std::vector<SurfacePoint> points;
  for (uint32_t v = 0; v < views.size(); ++v) {
    const cv::Mat& depth = views[v].depth;
    for (int y = 0; y < depth.rows; y += step) {
      for (int x = 0; x < depth.cols; x += step) {
        const float d = depth.at<float>(y, x);
        if (!std::isfinite(d)) continue;
        SurfacePoint point;
        point.X_W = views[v].view.camera.backProject(Eigen::Vector2d(x, y), d);
        point.depth_sigma_m = 0.0;
        point.views = {v};
        points.push_back(point);
      }
    }
  }
  return points;
}

inline std::vector<PinholeCamera> camerasOf(const std::vector<RenderedView>& views) {
  std::vector<PinholeCamera> cameras;
  for (const RenderedView& view : views) cameras.push_back(view.view.camera);
  return cameras;
}

}  // namespace sift_hull
