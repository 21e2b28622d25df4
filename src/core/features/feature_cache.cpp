#include "sift_hull/features/feature_cache.h"

#include <algorithm>
#include <string_view>

namespace sift_hull {

FeatureCache::FeatureCache(size_t capacity) : capacity_(std::max<size_t>(capacity, 1)) {}

std::shared_ptr<const Features> FeatureCache::get(uint64_t key,
                                                  const std::function<Features()>& compute) {
  std::promise<std::shared_ptr<const Features>> promise;
  std::shared_future<std::shared_ptr<const Features>> future;
  bool mine = false;
  {
    std::lock_guard<std::mutex> lock(mutex_);
    const auto found = std::find_if(entries_.begin(), entries_.end(),
                                    [&](const Entry& entry) { return entry.first == key; });
    if (found != entries_.end()) {
      ++hits_;
      entries_.splice(entries_.begin(), entries_, found);
      future = found->second;
    } else {
      ++misses_;
      mine = true;
      future = promise.get_future().share();
      entries_.emplace_front(key, future);
      if (entries_.size() > capacity_) entries_.pop_back();
    }
  }
  if (mine) {
    try {
      promise.set_value(std::make_shared<const Features>(compute()));
    } catch (...) {
      promise.set_exception(std::current_exception());
      std::lock_guard<std::mutex> lock(mutex_);
      entries_.remove_if([&](const Entry& entry) { return entry.first == key; });
    }
  }
  return future.get();
}

size_t FeatureCache::hits() const {
  std::lock_guard<std::mutex> lock(mutex_);
  return hits_;
}

size_t FeatureCache::misses() const {
  std::lock_guard<std::mutex> lock(mutex_);
  return misses_;
}

void FeatureCache::clear() {
  std::lock_guard<std::mutex> lock(mutex_);
  entries_.clear();
}

uint64_t imageKey(const cv::Mat& image) {
  uint64_t key = std::hash<std::string_view>()(
      std::string_view(reinterpret_cast<const char*>(&image.rows), sizeof(int)));
  const auto mix = [&](uint64_t value) {
    key ^= value + 0x9e3779b97f4a7c15ull + (key << 6) + (key >> 2);
  };
  mix(static_cast<uint64_t>(image.cols));
  mix(static_cast<uint64_t>(image.type()));
  for (int r = 0; r < image.rows; ++r) {
    const std::string_view row(reinterpret_cast<const char*>(image.ptr(r)),
                               image.cols * image.elemSize());
    mix(std::hash<std::string_view>()(row));
  }
  return key;
}

}  // namespace sift_hull
