#pragma once

// The cup scenes of the hull node's carving rostests (hull_refine, hull_photo): the hull rostests'
// views (320x240, on a sphere) of the cup, their poses in tf, and how much of the pocket and of
// the cup an octomap holds.

#include <geometry_msgs/TransformStamped.h>
#include <octomap/OcTree.h>
#include <tf2_ros/static_transform_broadcaster.h>

#include <functional>
#include <vector>

#include "hull_node_fixture.h"
#include "lib/conversions.h"
#include "sift_hull/synthetic/scene.h"
#include "sift_hull/synthetic/shape.h"

namespace sift_hull {
namespace test {

inline SceneConfig cupScene(int views) {
  SceneConfig config = sphereSceneConfig();
  config.shape = "cup";
  config.views = views;
  return config;
}

/// The first `count` views' camera poses in tf (world -> camera_<v>), as the node looks them up.
inline void sendCameraPoses(tf2_ros::StaticTransformBroadcaster* tf,
                            const std::vector<RenderedView>& views, size_t count) {
  std::vector<geometry_msgs::TransformStamped> poses;
  for (size_t v = 0; v < count && v < views.size(); ++v) {
    poses.push_back(ros_conversions::cameraPoseMessage(views[v].view.camera, "world",
                                                       frameOf(static_cast<int>(v)), {}));
  }
  tf->sendTransform(poses);
}

using Region = std::function<bool(const Eigen::Vector3d&)>;

/// The fraction of the `inside` points of a 40^3 grid over the cup's cube that `map` holds
/// occupied.
inline double occupiedFraction(const octomap::OcTree& map, const Region& inside) {
  const Eigen::Vector3d lo(-0.75, -0.75, -0.65), hi(0.75, 0.75, 0.65);
  size_t in = 0, occupied = 0;
  const int n = 40;
  for (int k = 0; k < n; ++k) {
    for (int j = 0; j < n; ++j) {
      for (int i = 0; i < n; ++i) {
        const Eigen::Vector3d X =
            lo + (hi - lo).cwiseProduct((Eigen::Vector3d(i, j, k).array() + 0.5).matrix() / n);
        if (!inside(X)) continue;
        ++in;
        const octomap::OcTreeNode* node = map.search(X.x(), X.y(), X.z());
        occupied += node != nullptr && map.isNodeOccupied(node) ? 1 : 0;
      }
    }
  }
  return in == 0 ? 0.0 : static_cast<double>(occupied) / in;
}

/// The cup's pocket (its cut filled, less the cup) and the cup itself.
struct CupRegions {
  Shape cup = Shape::byName("cup");
  Shape filled = cup.withoutCuts();
  Region pocket = [this](const Eigen::Vector3d& X) {
    return filled.contains(X) && !cup.contains(X);
  };
  Region solid = [this](const Eigen::Vector3d& X) { return cup.contains(X); };
  CupRegions() = default;
  CupRegions(const CupRegions&) = delete;
  CupRegions& operator=(const CupRegions&) = delete;
};

}  // namespace test
}  // namespace sift_hull
