#include "sift_hull/hull/hull_pipeline.h"

#include <algorithm>
#include <chrono>
#include <memory>
#include <stdexcept>

#include "common/parallel.h"
#include "sift_hull/geometry/camera_set.h"
#include "sift_hull/hull/bounding_box.h"
#include "sift_hull/hull/reduced_distance_map.h"

namespace sift_hull {
namespace {

using Clock = std::chrono::steady_clock;

double millisecondsSince(Clock::time_point start) {
  return std::chrono::duration<double, std::milli>(Clock::now() - start).count();
}

/// The input's silhouettes run-length encoded (those given as images on `threads` threads).
std::vector<RunLengthMask> encodedMasks(const HullInput& input, int threads) {
  if (input.masks.empty()) return input.run_length_masks;
  std::vector<RunLengthMask> encoded(input.masks.size());
  detail::parallelFor(encoded.size(), threads,
                      [&](size_t i) { encoded[i] = RunLengthMask(input.masks[i]); });
  return encoded;
}

/// The views of a box, each with the distance reduction distanceReduction() chooses for it.
std::vector<HullView> viewsFor(const HullInput& input, std::vector<RunLengthMask>* masks,
                               const Box3d& box, const HullConfig& config) {
  std::vector<std::unique_ptr<HullView>> made(masks->size());
  detail::parallelFor(made.size(), config.threads, [&](size_t i) {
    const int reduction = distanceReduction(input.cameras[i], (*masks)[i].size(), box, config);
    made[i] = std::make_unique<HullView>(input.names[i], input.cameras[i], std::move((*masks)[i]),
                                         config, reduction);
  });
  std::vector<HullView> views;
  views.reserve(made.size());
  for (auto& view : made) views.push_back(std::move(*view));
  return views;
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
                     const std::optional<Box3d>& box,
                     const std::function<void(const std::string& stage)>& on_stage) {
  const auto starting = [&](const std::string& stage) {
    if (on_stage) on_stage(stage);
  };
  validate(config);
  HullTimings time;
  const size_t count = input.viewCount();
  if (input.names.size() != count || input.cameras.size() != count) {
    throw std::invalid_argument("buildHull: names, cameras and masks differ in count");
  }
  const Clock::time_point start = Clock::now();
  std::vector<RunLengthMask> masks = encodedMasks(input, config.threads);
  std::vector<SilhouetteBounds> bounds(count);
  detail::parallelFor(count, config.threads, [&](size_t i) {
    bounds[i] = viewBounds(input.names[i], input.cameras[i], masks[i], config);
  });
  time.masks_ms = millisecondsSince(start);

  Clock::time_point stage = Clock::now();
  // One camera far from the others would set the LP's frame and scale, and the LP would then
  // blame the others; it is named here instead.
  if (!box) requireNoStrayCamera(input.cameras, input.names);
  const Box3d hull_box = box ? *box : hullBoundingBox(input.cameras, bounds, input.names);
  time.bbox_ms = millisecondsSince(stage);

  starting("distance maps");
  stage = Clock::now();
  std::vector<HullView> views = viewsFor(input, &masks, hull_box, config);
  time.distance_ms = millisecondsSince(stage);

  starting("octree");
  stage = Clock::now();
  VisualHull hull(hull_box, config);
  hull.addViews(std::move(views));
  time.octree_ms = millisecondsSince(stage);

  starting("mesh");
  stage = Clock::now();
  TriangleMesh mesh = hull.mesh();
  time.mesh_ms = millisecondsSince(stage);
  time.total_ms = millisecondsSince(start);
  const MeshCheck check = checkMesh(mesh);
  return {hull_box, std::move(hull), std::move(mesh), check, time};
}

}  // namespace sift_hull
