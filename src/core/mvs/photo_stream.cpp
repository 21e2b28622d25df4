#include "sift_hull/mvs/photo_stream.h"

#include <algorithm>
#include <chrono>
#include <stdexcept>
#include <utility>

namespace sift_hull {

template <>
const SettingTable<PhotoStreamConfig>& settingsOf<PhotoStreamConfig>() {
  static const SettingTable<PhotoStreamConfig> table = [] {
    SettingTable<PhotoStreamConfig> t;
    t.add("photo_max_views", &PhotoStreamConfig::photo_max_views, "views",
          "views whose photographs photo carving keeps (each: 4 bytes a pixel); later views "
          "carve by their silhouettes only")
        .range(2, 4096);
    t.nest("", &PhotoStreamConfig::carve, settingsOf<PhotoCarveConfig>());
    return t;
  }();
  return table;
}

void validate(const PhotoStreamConfig& config) { checkSettings(config, "PhotoStreamConfig"); }

PhotoStream::PhotoStream(PhotoStreamConfig config, std::function<void()> on_done)
    : config_(std::move(config)), on_done_(std::move(on_done)) {
  validate(config_);
}

PhotoStream::~PhotoStream() { join(); }

void PhotoStream::join() {
  if (worker_.joinable()) worker_.join();
}

bool PhotoStream::add(const std::string& name, const PinholeCamera& camera, const cv::Mat& image,
                      const cv::Mat& mask) {
  const bool image_ok = image.depth() == CV_8U &&
                        (image.channels() == 1 || image.channels() == 3 || image.channels() == 4);
  if (!image_ok) {
    throw std::invalid_argument("view '" + name +
                                "': the photograph is not an 8-bit grey or colour image");
  }
  if (mask.type() != CV_8UC1 || mask.size() != image.size()) {
    throw std::invalid_argument(
        "view '" + name + "': the silhouette (" + std::to_string(mask.cols) + "x" +
        std::to_string(mask.rows) + ") is not 8-bit of the photograph's size (" +
        std::to_string(image.cols) + "x" + std::to_string(image.rows) + ")");
  }
  if (views_.size() >= static_cast<size_t>(config_.photo_max_views)) {
    ++left_out_;
    return false;
  }
  views_.push_back(Kept{name, camera, image.clone(), mask.clone()});
  added_since_pass_ = true;
  return true;
}

void PhotoStream::remove(const std::string& name) {
  const size_t before = views_.size();
  views_.erase(std::remove_if(views_.begin(), views_.end(),
                              [&](const Kept& kept) { return kept.name == name; }),
               views_.end());
  if (views_.size() != before) added_since_pass_ = true;
}

bool PhotoStream::startIfDue(const VisualHull& hull, uint64_t generation) {
  if (worker_.joinable()) {
    std::lock_guard<std::mutex> lock(shared_->mutex);
    if (!shared_->ended) return false;  // one pass at a time
  }
  const bool due = added_since_pass_ || !any_pass_ || generation != pass_generation_;
  if (views_.size() < 2 || !due) return false;
  join();  // the last pass has ended: at once
  if (shared_ && !discard_) {
    std::lock_guard<std::mutex> lock(shared_->mutex);
    if (shared_->pass) return false;  // ended but not yet taken: the owner takes it first
  }
  added_since_pass_ = false;
  any_pass_ = true;
  discard_ = false;
  pass_generation_ = generation;
  ++passes_;
  shared_ = std::make_shared<Shared>();
  // The copy and the views' list are the pass's own: the images are shared, never changed.
  auto copy = std::make_shared<VisualHull>(hull.clone());
  std::vector<Kept> views = views_;
  const PhotoCarveConfig config = config_.carve;
  worker_ = std::thread(
      [shared = shared_, copy, views = std::move(views), config, generation, on_done = on_done_] {
        std::unique_ptr<Pass> pass = run(copy.get(), views, config);
        pass->generation = generation;
        {
          std::lock_guard<std::mutex> lock(shared->mutex);
          shared->pass = std::move(pass);
          shared->ended = true;
        }
        if (on_done) on_done();
      });
  return true;
}

std::unique_ptr<PhotoStream::Pass> PhotoStream::run(VisualHull* copy,
                                                    const std::vector<Kept>& views,
                                                    const PhotoCarveConfig& config) {
  const auto start = std::chrono::steady_clock::now();
  auto pass = std::make_unique<Pass>();
  pass->views = views.size();
  try {
    PhotoViews photo_views;
    for (const Kept& kept : views) photo_views.cameras.push_back(kept.camera);
    photo_views.image = [&views](uint32_t i) { return views[i].image; };
    photo_views.mask = [&views](uint32_t i) { return views[i].mask; };
    pass->carving = photoCarve(*copy, photo_views, config);
    pass->carving.depths.clear();
    pass->carving.depths.shrink_to_fit();
    copy->carveFree(pass->carving.free_voxels);
    pass->mesh = copy->mesh();
    pass->colouring =
        colourMesh(&pass->mesh, photo_views.cameras, photo_views.image, copy->config().threads);
  } catch (const std::exception& e) {
    pass->error = e.what();
  }
  pass->total_ms =
      std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count();
  return pass;
}

std::unique_ptr<PhotoStream::Pass> PhotoStream::takeDone() {
  if (!shared_) return nullptr;
  std::unique_ptr<Pass> pass;
  {
    std::lock_guard<std::mutex> lock(shared_->mutex);
    if (!shared_->ended) return nullptr;
    pass = std::move(shared_->pass);
  }
  join();
  if (discard_) return nullptr;
  return pass;
}

void PhotoStream::reset() {
  views_.clear();
  left_out_ = 0;
  added_since_pass_ = false;
  any_pass_ = false;
  discard_ = worker_.joinable();
}

}  // namespace sift_hull
