#pragma once

#include <nlohmann/json.hpp>
#include <optional>
#include <string>

#include "args.h"
#include "sift_hull/hull/hull_pipeline.h"

namespace sift_hull {
namespace cli {

/// --refine-with-matches, --match-pairs, --filter, the SurfacePointConfig and FreeSpaceConfig
/// settings under their field names, and --gt-scene.
void addRefineOptions(ArgParser* parser);

/// With --refine-with-matches: throws UsageError for a bad refinement setting (before the hull is
/// built).
void checkRefineOptions(const ArgParser& parser);

/// With --refine-with-matches: SIFT on every view's image (--images), the chosen pairs matched
/// and filtered, triangulated into consistent surface points, their lines of sight carved from
/// result->hull and the mesh made again. Returns the JSON it adds to `hull --json` ("points",
/// "carved_volume_m3", and with --gt-scene the comparison with the rendered solid), an empty
/// object without either flag. Throws UsageError for bad settings.
nlohmann::json refineWithMatches(const ArgParser& parser, const HullInput& input,
                                 HullResult* result);

/// With --out-mesh or --out-color-octree, and --images: each vertex of result->mesh coloured by the
/// views that see it (sift_hull::colourMesh). Returns its part of `hull --json` ("mesh_colours"),
/// an empty object otherwise.
nlohmann::json colourMesh(const ArgParser& parser, const HullInput& input, HullResult* result);

/// The view --holdout-view names, taken out of the views the hull is built from.
struct HeldOutView {
  std::string name;
  PinholeCamera camera;
  cv::Mat mask;  ///< CV_8UC1
};

/// With --holdout-view NAME: that view, removed from *input; throws UsageError without --images
/// or for a name that is not one of the views.
std::optional<HeldOutView> holdOutView(const ArgParser& parser, HullInput* input);

/// `mesh` coloured by the views of `input` (unless it has a colour per vertex already, which
/// colourMesh gave it from the same views) and rendered into the held-out view: its colour error
/// against the photograph inside the view's silhouette ({"mae", "psnr_db"}).
nlohmann::json heldOutError(const ArgParser& parser, const HullInput& input,
                            const HeldOutView& view, TriangleMesh mesh, int threads);

}  // namespace cli
}  // namespace sift_hull
