#pragma once

#include <cstdint>
#include <functional>
#include <future>
#include <list>
#include <memory>
#include <mutex>
#include <utility>

#include "sift_hull/features/sift.h"

namespace sift_hull {

/// The SIFT features of the last few images, by a key of the caller's (the matcher node: a hash
/// of the image's pixels, so that an image in two pairs, frame to frame or the (k, k+1) pairs of a
/// stereo sequence, is described once). Thread-safe; concurrent requests for one key compute it
/// once, the others wait for that result. Holds at most `capacity` entries (the least recently
/// used go first), so memory stays bounded whatever the stream.
class FeatureCache {
 public:
  explicit FeatureCache(size_t capacity = 8);

  /// The features under `key`, from `compute` when absent. An exception from `compute` reaches
  /// every caller waiting for that key, and the key is not cached.
  std::shared_ptr<const Features> get(uint64_t key, const std::function<Features()>& compute);

  size_t hits() const;
  size_t misses() const;
  void clear();

 private:
  using Entry = std::pair<uint64_t, std::shared_future<std::shared_ptr<const Features>>>;
  size_t capacity_;
  mutable std::mutex mutex_;
  std::list<Entry> entries_;  ///< most recently used first
  size_t hits_ = 0, misses_ = 0;
};

/// A 64-bit key of an image's content: its size, type and every pixel.
uint64_t imageKey(const cv::Mat& image);

}  // namespace sift_hull
