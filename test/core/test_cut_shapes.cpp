// The renderer's cuts: the concave shapes' depth maps against brute-force sampling along the
// pixels' rays.

#include <gtest/gtest.h>

#include <cmath>
#include <string>

#include "sift_hull/synthetic/scene.h"
#include "sift_hull/synthetic/shape.h"

namespace sift_hull {
namespace {

/// The concave shapes' depth maps against brute force: the first of fine samples along the
/// pixel's ray that lies inside the solid (sharing no formula with the renderer's cut handling),
/// where the ray enters it. Pixels of the cavities included: the renderer must see the pocket's
/// floor and inner walls, not the cut's box.
TEST(Shape, CutShapesAreRenderedWhereTheirRaysFirstEnterTheSolid) {
  for (const std::string name : {"cup", "ublock"}) {
    SceneConfig config;
    config.shape = name;
    config.views = 4;
    config.layout = "sphere";
    config.width_px = 160;
    config.height_px = 120;
    const Shape shape = Shape::byName(name);
    ASSERT_TRUE(shape.hasCuts());
    size_t compared = 0, deeper_than_box = 0;
    for (const RenderedView& view : renderScene(config)) {
      const PinholeCamera& camera = view.view.camera;
      for (int v = 0; v < 120; v += 3) {
        for (int u = 0; u < 160; u += 3) {
          const float depth = view.depth.at<float>(v, u);
          const Eigen::Vector3d origin = camera.centre();
          const Eigen::Vector3d direction = camera.rayDirection(Eigen::Vector2d(u, v));
          const double first = (shape.boundingCentre() - origin).norm() - shape.boundingRadius();
          double entered = -1.0;
          for (double s = first; s < first + 2.0 * shape.boundingRadius(); s += 2e-4) {
            if (shape.contains(origin + s * direction)) {
              entered = s;
              break;
            }
          }
          ASSERT_EQ(std::isfinite(depth), entered > 0.0) << name << " " << u << ", " << v;
          if (entered < 0.0) continue;
          const double entered_depth = camera.depth(origin + entered * direction);
          EXPECT_NEAR(depth, entered_depth, 1e-3) << name << " " << u << ", " << v;
          ++compared;
          // The shape without its cut would be entered earlier: the ray went into the cavity.
          Shape filled({shape.parts().front()});
          RayHit outer;
          if (filled.firstHit(origin, direction, &outer) && outer.distance_m < entered - 0.05) {
            ++deeper_than_box;
          }
        }
      }
    }
    EXPECT_GT(compared, 1000u) << name;
    EXPECT_GT(deeper_than_box, 50u) << name << ": no ray went into the cavity";
  }
}

}  // namespace
}  // namespace sift_hull
