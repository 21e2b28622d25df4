#include "sift_hull/hull/hull_pipeline.h"

#include <algorithm>
#include <chrono>
#include <stdexcept>

#include "sift_hull/hull/bounding_box.h"

namespace sift_hull {
namespace {

using Clock = std::chrono::steady_clock;

double millisecondsSince(Clock::time_point start) {
  return std::chrono::duration<double, std::milli>(Clock::now() - start).count();
}

}  // namespace

Box3d boundingBoxOf(const std::vector<HullView>& views) {
  std::vector<PinholeCamera> cameras;
  std::vector<SilhouetteBounds> bounds;
  std::vector<std::string> names;
  for (const HullView& view : views) {
    cameras.push_back(view.camera());
    bounds.push_back(view.bounds());
    names.push_back(view.name());
  }
  return hullBoundingBox(cameras, bounds, names);
}

HullResult buildHull(const HullInput& input, const HullConfig& config,
                     const std::optional<Box3d>& box) {
  validate(config);
  HullTimings time;
  const Clock::time_point start = Clock::now();
  std::vector<HullView> views = makeHullViews(input.names, input.cameras, input.masks, config);
  time.distance_ms = millisecondsSince(start);

  Clock::time_point stage = Clock::now();
  const Box3d hull_box = box ? *box : boundingBoxOf(views);
  time.bbox_ms = millisecondsSince(stage);

  stage = Clock::now();
  VisualHull hull(hull_box, config);
  hull.addViews(std::move(views));
  time.octree_ms = millisecondsSince(stage);

  stage = Clock::now();
  TriangleMesh mesh = hull.mesh();
  time.mesh_ms = millisecondsSince(stage);
  time.total_ms = millisecondsSince(start);
  const MeshCheck check = checkMesh(mesh);
  return {hull_box, std::move(hull), std::move(mesh), check, time};
}

}  // namespace sift_hull
