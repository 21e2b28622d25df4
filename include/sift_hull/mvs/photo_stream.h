#pragma once

#include <cstddef>
#include <cstdint>
#include <functional>
#include <memory>
#include <mutex>
#include <opencv2/core.hpp>
#include <string>
#include <thread>
#include <vector>

#include "sift_hull/geometry/camera.h"
#include "sift_hull/hull/mesh.h"
#include "sift_hull/hull/octree.h"
#include "sift_hull/mvs/mesh_colour.h"
#include "sift_hull/mvs/photo_carving.h"
#include "sift_hull/settings.h"

namespace sift_hull {

/// Photo carving of a hull that grows view by view (the hull node's `~photo_carve`).
struct PhotoStreamConfig {
  /// Views whose photographs are kept; later views still carve the hull by their silhouettes,
  /// but no pass sees them (counted). Memory: each view kept holds its photograph (3 bytes a
  /// pixel, 1 for grey) and its silhouette (1 byte a pixel).
  int photo_max_views = 64;
  PhotoCarveConfig carve;
};
/// Its settings: names, units, ranges, help (sift_hull/settings.h); `carve` nested without a
/// prefix (its names begin with photo_ already).
template <>
const SettingTable<PhotoStreamConfig>& settingsOf<PhotoStreamConfig>();

/// Throws std::invalid_argument naming the first bad field.
void validate(const PhotoStreamConfig& config);

/// Keeps the photographs of the views a hull was carved with, and runs passes of photoCarve on
/// a copy of the hull (VisualHull::clone) on a thread of its own, so that the hull's owner goes on
/// carving views meanwhile: each pass makes the depth maps of every view kept, carves the copy,
/// meshes it and colours the mesh (colourMesh). The owner takes a finished pass (takeDone) and
/// carves its free voxels into the hull when the hull's tree is still the one the pass copied.
///
/// Threads: one caller at a time (the hull's owner); `on_done` runs on the pass's thread.
class PhotoStream {
 public:
  /// `on_done` is called on the pass's thread as a pass ends (may be empty). Throws
  /// std::invalid_argument for a bad config.
  PhotoStream(PhotoStreamConfig config, std::function<void()> on_done);
  /// Waits for a pass that runs.
  ~PhotoStream();
  PhotoStream(const PhotoStream&) = delete;
  PhotoStream& operator=(const PhotoStream&) = delete;

  /// Keeps a view carved into the hull: its photograph (8-bit grey, BGR or BGRA) and silhouette
  /// (CV_8UC1), both of the size the camera was calibrated for, copied. False when
  /// photo_max_views are kept already. Throws std::invalid_argument for another image type or a
  /// silhouette of another size than the photograph.
  bool add(const std::string& name, const PinholeCamera& camera, const cv::Mat& image,
           const cv::Mat& mask);
  /// Forgets the views of that name (the hull refused them after all).
  void remove(const std::string& name);

  /// Starts a pass on a copy of `hull`, whose tree is `generation` (HullStream::hullGeneration),
  /// when none runs and one is due: two views kept at least, and views kept since the last pass
  /// began or a tree other than the last pass's. Returns whether it started.
  bool startIfDue(const VisualHull& hull, uint64_t generation);

  /// A finished pass.
  struct Pass {
    uint64_t generation = 0;   ///< of the tree it copied
    size_t views = 0;          ///< views it used
    PhotoCarveResult carving;  ///< without the depth maps
    TriangleMesh mesh;         ///< the carved copy's mesh, coloured
    MeshColouring colouring;
    double total_ms = 0.0;  ///< copy, carving, mesh and colours
    std::string error;      ///< why it failed (nothing else is set then); empty: it did not
  };
  /// The pass that ended since the last call, or null (none ran, it is still running, or reset()
  /// discarded it).
  std::unique_ptr<Pass> takeDone();

  /// Forgets every view; a pass that runs is discarded when it ends (not waited for).
  void reset();

  size_t keptViews() const { return views_.size(); }
  /// Views not kept since the start or the last reset (photo_max_views).
  size_t leftOutViews() const { return left_out_; }
  size_t passes() const { return passes_; }

 private:
  struct Kept {
    std::string name;
    PinholeCamera camera;
    cv::Mat image, mask;
  };
  /// What a pass's thread hands over.
  struct Shared {
    std::mutex mutex;
    std::unique_ptr<Pass> pass;
    bool ended = false;
  };
  static std::unique_ptr<Pass> run(VisualHull* copy, const std::vector<Kept>& views,
                                   const PhotoCarveConfig& config);
  void join();

  const PhotoStreamConfig config_;
  std::function<void()> on_done_;
  std::vector<Kept> views_;
  size_t left_out_ = 0, passes_ = 0;
  bool added_since_pass_ = false;
  bool any_pass_ = false;
  uint64_t pass_generation_ = 0;  ///< of the last pass started
  bool discard_ = false;          ///< the pass that runs began before a reset()
  std::shared_ptr<Shared> shared_;
  std::thread worker_;
};

}  // namespace sift_hull
