// The matches refinement of a hull: view pairs chosen, each run through runPair, dense matching,
// surface points and the free space they show (src/core/refine).

#include "sift_hull/pipeline/match_refinement.h"

#include <algorithm>
#include <chrono>
#include <set>
#include <stdexcept>

namespace sift_hull {
namespace {

using Clock = std::chrono::steady_clock;

double lapMs(Clock::time_point* start) {
  const Clock::time_point now = Clock::now();
  const double ms = std::chrono::duration<double, std::milli>(now - *start).count();
  *start = now;
  return ms;
}

/// Each view's image and dense-matching view, made when first needed.
class ViewStore {
 public:
  ViewStore(const RefineViews& views, int patch_radius_px)
      : views_(views), patch_radius_px_(patch_radius_px), store_(views.cameras.size()) {}

  const cv::Mat& image(uint32_t view) {
    Stored& s = store_.at(view);
    if (s.image.empty()) s.image = views_.image(view);
    if (s.image.empty()) {
      throw std::invalid_argument("refineWithMatches: view " + std::to_string(view) +
                                  " has no image");
    }
    return s.image;
  }
  const DenseView& dense(uint32_t view) {
    Stored& s = store_.at(view);
    if (s.dense.grey.empty()) {
      s.dense = denseMatchingView(image(view), views_.mask(view), patch_radius_px_);
    }
    return s.dense;
  }

 private:
  struct Stored {
    cv::Mat image;
    DenseView dense;
  };
  const RefineViews& views_;
  int patch_radius_px_;
  std::vector<Stored> store_;
};

/// Each pair's kept SIFT matches, then (dense matching on) each pair's dense matches.
void matchPairs(const RefineViews& views, const VisualHull& hull, const MatchFilter& filter,
                const MatchRefineConfig& config, FeatureCache* cache, MatchRefineResult* result) {
  ViewStore store(views, config.dense.patch_radius_px);
  const std::vector<const MatchFilter*> filters = {&filter};
  for (const auto& [a, b] : result->view_pairs) {
    PairInput input;
    input.left_image = store.image(a), input.right_image = store.image(b);
    input.cameras = std::make_pair(views.cameras[a], views.cameras[b]);
    input.left_view = a, input.right_view = b;
    input.min_keypoints = 0;  // every pair filtered, however few its features
    // One SIFT at a time (the memory of one image's pyramid); runPair finds both in the cache.
    describeImage(input.left_image, config.pair.sift, cache);
    describeImage(input.right_image, config.pair.sift, cache);
    PairResult pair = runPair(input, config.pair, filters, cache);
    result->sift_matches += pair.kept.left_px.size();
    result->pairs.push_back(std::move(pair.kept));
  }
  if (config.dense.grid_step_px == 0) return;
  for (const auto& [a, b] : result->view_pairs) {
    result->pairs.push_back(denseMatches(store.dense(a), store.dense(b), views.cameras[a],
                                         views.cameras[b], a, b, hull, config.dense,
                                         hull.config().threads));
    result->dense_matches += result->pairs.back().left_px.size();
  }
}

}  // namespace

void validate(const MatchRefineConfig& config) {
  validate(config.pair);
  validate(config.dense);
  validate(config.points);
  validate(config.free_space);
}

std::vector<std::pair<uint32_t, uint32_t>> refinementViewPairs(
    const std::vector<PinholeCamera>& cameras, ViewPairing pairing) {
  std::set<std::pair<uint32_t, uint32_t>> pairs;
  const uint32_t n = static_cast<uint32_t>(cameras.size());
  for (uint32_t a = 0; a < n; ++a) {
    std::vector<uint32_t> others;
    for (uint32_t b = 0; b < n; ++b) {
      if (b != a) others.push_back(b);
    }
    const Eigen::Vector3d centre = cameras[a].centre();
    std::sort(others.begin(), others.end(), [&](uint32_t x, uint32_t y) {
      return (cameras[x].centre() - centre).norm() < (cameras[y].centre() - centre).norm();
    });
    if (pairing == ViewPairing::kNeighbours && others.size() > kPairingNeighbours) {
      others.resize(kPairingNeighbours);
    }
    for (const uint32_t b : others) pairs.insert({std::min(a, b), std::max(a, b)});
  }
  return {pairs.begin(), pairs.end()};
}

void surfacePointsAndFreeSpace(const std::vector<PinholeCamera>& cameras,
                               const std::vector<PairMatches>& pairs, const VisualHull& hull,
                               const MatchRefineConfig& config, MatchRefineResult* result) {
  Clock::time_point start = Clock::now();
  result->points = surfacePoints(cameras, pairs, hull, config.points, &result->counts);
  result->times_ms.points = lapMs(&start);
  result->free_voxels = freeVoxels(hull, cameras, result->points, config.free_space);
  result->times_ms.free_voxels = lapMs(&start);
}

MatchRefineResult refineWithMatches(const RefineViews& views, const VisualHull& hull,
                                    const MatchFilter& filter, const MatchRefineConfig& config,
                                    FeatureCache* cache) {
  validate(config);
  if (!views.image) throw std::invalid_argument("refineWithMatches: no image function");
  if (config.dense.grid_step_px > 0 && !views.mask) {
    throw std::invalid_argument("refineWithMatches: dense matching needs the views' masks");
  }
  MatchRefineResult result;
  Clock::time_point start = Clock::now();
  result.view_pairs = refinementViewPairs(views.cameras, config.pairing);
  FeatureCache own(std::max<size_t>(views.cameras.size(), 1));
  matchPairs(views, hull, filter, config, cache != nullptr ? cache : &own, &result);
  result.times_ms.matching = lapMs(&start);
  surfacePointsAndFreeSpace(views.cameras, result.pairs, hull, config, &result);
  return result;
}

}  // namespace sift_hull
