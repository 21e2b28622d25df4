// The matcher's feature cache: each key computed once (also under concurrent requests), bounded,
// exceptions passed on and not cached; image keys that follow the pixels.
#include <gtest/gtest.h>

#include <atomic>
#include <chrono>
#include <stdexcept>
#include <thread>
#include <vector>

#include "sift_hull/features/feature_cache.h"

namespace sift_hull {
namespace {

Features featuresOfSize(size_t n) {
  Features features;
  features.keypoints.resize(n);
  return features;
}

TEST(FeatureCache, ComputesEachKeyOnceAndEvictsTheLeastRecentlyUsed) {
  FeatureCache cache(2);
  int computed = 0;
  const auto compute = [&](size_t n) {
    return [&computed, n] {
      ++computed;
      return featuresOfSize(n);
    };
  };
  EXPECT_EQ(cache.get(1, compute(1))->keypoints.size(), 1u);
  EXPECT_EQ(cache.get(1, compute(99))->keypoints.size(), 1u);  // cached: not recomputed
  EXPECT_EQ(cache.get(2, compute(2))->keypoints.size(), 2u);
  cache.get(1, compute(99));                                   // 1 is now the most recent
  EXPECT_EQ(cache.get(3, compute(3))->keypoints.size(), 3u);  // evicts 2
  EXPECT_EQ(computed, 3);
  EXPECT_EQ(cache.get(1, compute(99))->keypoints.size(), 1u);
  EXPECT_EQ(cache.get(2, compute(4))->keypoints.size(), 4u);  // recomputed after eviction
  EXPECT_EQ(computed, 4);
  EXPECT_EQ(cache.hits(), 3u);
  EXPECT_EQ(cache.misses(), 4u);
}

TEST(FeatureCache, ConcurrentRequestsForOneKeyComputeItOnce) {
  FeatureCache cache(4);
  std::atomic<int> computed{0};
  std::vector<std::thread> threads;
  std::vector<size_t> sizes(8);
  for (int t = 0; t < 8; ++t) {
    threads.emplace_back([&, t] {
      sizes[t] = cache
                     .get(42,
                          [&] {
                            ++computed;
                            std::this_thread::sleep_for(std::chrono::milliseconds(50));
                            return featuresOfSize(7);
                          })
                     ->keypoints.size();
    });
  }
  for (std::thread& thread : threads) thread.join();
  EXPECT_EQ(computed.load(), 1);
  for (size_t size : sizes) EXPECT_EQ(size, 7u);
}

TEST(FeatureCache, AFailedComputationReachesTheCallerAndIsNotCached) {
  FeatureCache cache;
  EXPECT_THROW(cache.get(5, []() -> Features { throw std::invalid_argument("bad image"); }),
               std::invalid_argument);
  EXPECT_EQ(cache.get(5, [] { return featuresOfSize(3); })->keypoints.size(), 3u);
}

TEST(ImageKey, FollowsThePixelsNotTheBuffer) {
  cv::Mat image(48, 64, CV_8UC3, cv::Scalar(10, 20, 30));
  const uint64_t key = imageKey(image);
  EXPECT_EQ(imageKey(image.clone()), key);
  cv::Mat big(100, 100, CV_8UC3, cv::Scalar(0, 0, 0));
  image.copyTo(big(cv::Rect(5, 7, 64, 48)));
  EXPECT_EQ(imageKey(big(cv::Rect(5, 7, 64, 48))), key) << "a view with row padding";
  cv::Mat changed = image.clone();
  changed.at<cv::Vec3b>(47, 63)[2] = 31;
  EXPECT_NE(imageKey(changed), key);
  EXPECT_NE(imageKey(image.reshape(3, 64)), key) << "same bytes, other shape";
  cv::Mat grey(48, 64, CV_8UC1, cv::Scalar(10));
  EXPECT_NE(imageKey(grey), imageKey(cv::Mat(48, 64, CV_8UC1, cv::Scalar(11))));
}

}  // namespace
}  // namespace sift_hull
