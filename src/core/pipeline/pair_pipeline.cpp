// One pair of images through the method: SIFT, matching, calibration, the filters, and the first
// filter's kept matches triangulated. The matcher node, `sift_hull match` and the matches
// refinement (match_refinement.cpp) all run pairs through runPair.

#include "sift_hull/pipeline/pair_pipeline.h"

#include <algorithm>
#include <chrono>
#include <future>
#include <stdexcept>

namespace sift_hull {
namespace {

using Clock = std::chrono::steady_clock;

double millisecondsSince(Clock::time_point start) {
  return std::chrono::duration<double, std::milli>(Clock::now() - start).count();
}

/// describeImage, and the time it took.
std::shared_ptr<const Features> describe(const cv::Mat& image, const SiftConfig& sift,
                                         FeatureCache* cache, double* ms) {
  const Clock::time_point start = Clock::now();
  std::shared_ptr<const Features> features = describeImage(image, sift, cache);
  *ms = millisecondsSince(start);
  return features;
}

/// Putative matches of the described pair: guided along the epipolar lines, or every descriptor.
PutativeMatches matched(const PairInput& input, const PairPipelineConfig& config,
                        const Features& left, const Features& right) {
  if (config.epipolar_search_px > 0.0 && input.cameras) {
    PutativeMatches putative;
    putative.matches =
        matchAlongEpipolarLines(left, right, input.cameras->first, input.cameras->second,
                                config.matching, config.epipolar_search_px);
    putative.left_keypoints = left.keypoints;
    putative.right_keypoints = right.keypoints;
    putative.left_image_size = input.left_image.size();
    putative.right_image_size = input.right_image.size();
    return putative;
  }
  return matchFeatures(left, right, input.left_image.size(), input.right_image.size(),
                       config.matching);
}

void checkFilters(const std::vector<const MatchFilter*>& filters) {
  if (filters.empty()) throw std::invalid_argument("runPair: no filter");
  for (const MatchFilter* filter : filters) {
    if (filter == nullptr) throw std::invalid_argument("runPair: a null filter");
  }
}

}  // namespace

template <>
const SettingTable<PairPipelineConfig>& settingsOf<PairPipelineConfig>() {
  static const SettingTable<PairPipelineConfig> table = [] {
    SettingTable<PairPipelineConfig> t;
    t.nest("", &PairPipelineConfig::sift, settingsOf<SiftConfig>());
    t.nest("", &PairPipelineConfig::matching, settingsOf<MatchConfig>());
    t.add("epipolar_search_px", &PairPipelineConfig::epipolar_search_px, "px",
          "with cameras, match along the epipolar lines within this distance (0: match every "
          "descriptor)")
        .atLeast(0.0);
    return t;
  }();
  return table;
}

void validate(const PairPipelineConfig& config) {
  validate(config.sift);
  validate(config.matching);
  checkSettings(config, "PairPipelineConfig");
}

std::shared_ptr<const Features> describeImage(const cv::Mat& image, const SiftConfig& sift,
                                              FeatureCache* cache) {
  if (cache == nullptr) return std::make_shared<const Features>(detectSift(image, sift));
  return cache->get(imageKey(image), [&] { return detectSift(image, sift); });
}

PairMatches keptPairMatches(const PutativeMatches& putative, const std::vector<uint8_t>& kept,
                            uint32_t left_view, uint32_t right_view) {
  if (kept.size() != putative.matches.size()) {
    throw std::invalid_argument("keptPairMatches: " + std::to_string(kept.size()) + " flags for " +
                                std::to_string(putative.matches.size()) + " matches");
  }
  PairMatches pair;
  pair.left_view = left_view, pair.right_view = right_view;
  for (size_t m = 0; m < putative.matches.size(); ++m) {
    if (!kept[m]) continue;
    pair.left_px.emplace_back(putative.left(m).pt.x, putative.left(m).pt.y);
    pair.right_px.emplace_back(putative.right(m).pt.x, putative.right(m).pt.y);
    pair.left_keypoint.push_back(putative.matches[m].queryIdx);
    pair.right_keypoint.push_back(putative.matches[m].trainIdx);
  }
  return pair;
}

std::vector<const MatchFilter*> filterPointers(
    const std::vector<std::unique_ptr<MatchFilter>>& filters) {
  std::vector<const MatchFilter*> pointers;
  for (const auto& filter : filters) pointers.push_back(filter.get());
  return pointers;
}

PairResult runPair(const PairInput& input, const PairPipelineConfig& config,
                   const std::vector<const MatchFilter*>& filters, FeatureCache* cache) {
  validate(config);
  checkFilters(filters);
  PairResult result;
  // The right image on a second thread; the future's destructor waits for it, also on a throw.
  auto right = std::async(std::launch::async, describe, std::cref(input.right_image),
                          std::cref(config.sift), cache, &result.times.sift_right_ms);
  const std::shared_ptr<const Features> left =
      describe(input.left_image, config.sift, cache, &result.times.sift_left_ms);
  const std::shared_ptr<const Features> right_features = right.get();
  Clock::time_point start = Clock::now();
  result.putative = matched(input, config, *left, *right_features);
  result.times.matching_ms = millisecondsSince(start);
  const size_t fewest =
      std::min(result.putative.left_keypoints.size(), result.putative.right_keypoints.size());
  if (fewest < input.min_keypoints) {
    result.why_not =
        "fewer than " + (input.min_keypoints == 2 ? "two" : std::to_string(input.min_keypoints)) +
        " keypoints in an image (" + std::to_string(result.putative.left_keypoints.size()) +
        " and " + std::to_string(result.putative.right_keypoints.size()) + ")";
    return result;
  }
  if (input.cameras) {
    calibratePair(&result.putative, input.cameras->first, input.cameras->second);
  } else if (input.F_right_left) {
    result.putative.F_right_left = *input.F_right_left;
  }
  for (const MatchFilter* filter : filters) {
    start = Clock::now();
    FilterResult verdict = filter->apply(result.putative);
    result.verdicts.push_back({filter->name(), std::move(verdict), millisecondsSince(start)});
  }
  result.kept = keptPairMatches(result.putative, result.verdicts.front().result.keep,
                                input.left_view, input.right_view);
  if (!input.cameras) return result;
  start = Clock::now();
  result.surface_points = triangulatePair(input.cameras->first, input.cameras->second, result.kept);
  result.times.triangulation_ms = millisecondsSince(start);
  return result;
}

}  // namespace sift_hull
