// Exact nearest neighbours by matrix product against OpenCV's brute force and a scalar reference:
// the same neighbours up to exact ties (counted) and float rounding, across block boundaries. The
// integer kernel (byte descriptors, AVX-512 VNNI) exactly, ties included; the float32 kernel for
// everything else.
#include <gtest/gtest.h>

#include <cmath>
#include <iostream>
#include <limits>
#include <opencv2/features2d.hpp>
#include <opencv2/imgcodecs.hpp>
#include <random>
#include <set>
#include <vector>

#include "common/test_data.h"
#include "features/neighbour_kernels.h"
#include "sift_hull/features/matching.h"
#include "sift_hull/features/nearest_neighbours.h"
#include "sift_hull/features/sift.h"
#include "sift_hull/synthetic/scene.h"

namespace sift_hull {
namespace {

constexpr float kInf = std::numeric_limits<float>::infinity();

/// The plain reference: every distance, the two smallest kept (lowest index first among ties).
std::vector<TwoNearest> scalarReference(const cv::Mat& q, const cv::Mat& r) {
  std::vector<TwoNearest> out(q.rows, TwoNearest{-1, -1, kInf, kInf});
  for (int i = 0; i < q.rows; ++i) {
    for (int j = 0; j < r.rows; ++j) {
      const float d = static_cast<float>(cv::norm(q.row(i), r.row(j), cv::NORM_L2));
      TwoNearest& n = out[i];
      if (d < n.best_distance) {
        n.second = n.best, n.second_distance = n.best_distance, n.best = j, n.best_distance = d;
      } else if (d < n.second_distance) {
        n.second = j, n.second_distance = d;
      }
    }
  }
  return out;
}

cv::Mat randomDescriptors(int rows, int cols, bool integers, unsigned seed) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<float> value(0.0f, 60.0f);
  cv::Mat m(rows, cols, CV_32F);
  for (int i = 0; i < rows; ++i) {
    for (int k = 0; k < cols; ++k) {
      const float v = value(rng);
      m.at<float>(i, k) = integers ? std::floor(v) : v;
    }
  }
  return m;
}

/// Counts the queries whose neighbour differs from the expected one, failing on any that is not
/// an exact (or rounding-level) tie: the distance of the index found equals the expected distance.
int compareNeighbours(const std::vector<TwoNearest>& got, const std::vector<TwoNearest>& want,
                      float tolerance) {
  EXPECT_EQ(got.size(), want.size());
  int differ = 0;
  for (size_t i = 0; i < std::min(got.size(), want.size()); ++i) {
    EXPECT_NEAR(got[i].best_distance, want[i].best_distance, tolerance) << "query " << i;
    if (std::isfinite(want[i].second_distance)) {
      EXPECT_NEAR(got[i].second_distance, want[i].second_distance, tolerance) << "query " << i;
    } else {
      EXPECT_EQ(got[i].second, -1) << "query " << i;
    }
    differ += got[i].best != want[i].best;
  }
  return differ;
}

/// Byte-valued descriptors drawn from `levels` values spread over [0, 255]: few levels give many
/// exactly equal distances.
cv::Mat byteDescriptors(int rows, int cols, int levels, unsigned seed) {
  std::mt19937 rng(seed);
  std::uniform_int_distribution<int> level(0, levels - 1);
  cv::Mat m(rows, cols, CV_32F);
  for (int i = 0; i < rows; ++i) {
    for (int k = 0; k < cols; ++k) m.at<float>(i, k) = static_cast<float>(level(rng) * 255 / (levels - 1));
  }
  return m;
}

/// Integer squared distances, the two smallest per query and the nearest query per reference,
/// the lowest index first among equals: what the integer kernel must give exactly.
struct IntegerReference {
  std::vector<int> best, second, reverse;
  std::vector<int32_t> best_squared, second_squared;  ///< -1 where there is no neighbour
};

IntegerReference integerReference(const cv::Mat& q, const cv::Mat& r) {
  IntegerReference out{std::vector<int>(q.rows, -1), std::vector<int>(q.rows, -1),
                       std::vector<int>(r.rows, -1), std::vector<int32_t>(q.rows, -1),
                       std::vector<int32_t>(q.rows, -1)};
  std::vector<int64_t> reverse_best(r.rows, std::numeric_limits<int64_t>::max());
  for (int i = 0; i < q.rows; ++i) {
    int64_t b1 = std::numeric_limits<int64_t>::max(), b2 = b1;
    for (int j = 0; j < r.rows; ++j) {
      int64_t d2 = 0;
      for (int k = 0; k < q.cols; ++k) {
        const int64_t d = static_cast<int64_t>(q.at<float>(i, k)) - static_cast<int64_t>(r.at<float>(j, k));
        d2 += d * d;
      }
      if (d2 < b1) {
        b2 = b1, out.second[i] = out.best[i], b1 = d2, out.best[i] = j;
      } else if (d2 < b2) {
        b2 = d2, out.second[i] = j;
      }
      if (d2 < reverse_best[j]) reverse_best[j] = d2, out.reverse[j] = i;
    }
    if (out.best[i] >= 0) out.best_squared[i] = static_cast<int32_t>(b1);
    if (out.second[i] >= 0) out.second_squared[i] = static_cast<int32_t>(b2);
  }
  return out;
}

TEST(ExactNearestNeighbours, ByteKernelIsExactWithTiesAndOddShapes) {
  if (!detail::byteKernelAvailable()) {
    GTEST_SKIP() << "this CPU has no AVX-512 VNNI: the integer kernel does not run here";
  }
  int cases = 0;
  for (int cols : {1, 5, 128, 130}) {
    for (auto [nq, nr] : {std::pair{1, 1}, {1, 2}, {7, 15}, {17, 33}, {65, 31}, {300, 100},
                          {129, 545}}) {
      for (int levels : {2, 4, 256}) {
        const unsigned seed = static_cast<unsigned>(cols * 1000 + nq * 7 + nr + levels);
        const cv::Mat q = byteDescriptors(nq, cols, levels, seed);
        const cv::Mat r = byteDescriptors(nr, cols, levels, seed + 1);
        detail::ExactNeighbours got;
        ASSERT_TRUE(detail::byteNearestNeighbours(q, r, true, &got));
        const IntegerReference want = integerReference(q, r);
        const std::string what = std::to_string(nq) + " x " + std::to_string(nr) + ", " +
                                 std::to_string(cols) + " columns, " + std::to_string(levels) +
                                 " levels";
        EXPECT_EQ(got.best, want.best) << what;
        EXPECT_EQ(got.second, want.second) << what;
        EXPECT_EQ(got.reverse, want.reverse) << what;
        EXPECT_EQ(got.best_squared, want.best_squared) << what;
        EXPECT_EQ(got.second_squared, want.second_squared) << what;
        ++cases;
      }
    }
  }
  EXPECT_EQ(cases, 84);
}

TEST(ExactNearestNeighbours, ByteKernelSumsStayExactAtItsWidestDescriptors) {
  if (!detail::byteKernelAvailable()) {
    GTEST_SKIP() << "this CPU has no AVX-512 VNNI: the integer kernel does not run here";
  }
  // All 0 against all 255 over 1,024 columns: the largest squared distance, 66,585,600.
  cv::Mat q(3, detail::kMaxByteColumns, CV_32F, cv::Scalar(0.0f));
  q.row(1).setTo(255.0f);
  q.at<float>(2, 0) = 255.0f;
  const cv::Mat r = q.clone();
  detail::ExactNeighbours got;
  ASSERT_TRUE(detail::byteNearestNeighbours(q, r, true, &got));
  EXPECT_EQ(got.best, (std::vector<int>{0, 1, 2}));
  EXPECT_EQ(got.second, (std::vector<int>{2, 2, 0}));
  EXPECT_EQ(got.reverse, (std::vector<int>{0, 1, 2}));
  const NearestNeighbours full = exactNearestNeighbours(q, r, false);
  EXPECT_FLOAT_EQ(full.forward[1].second_distance, std::sqrt(1023.0f) * 255.0f);
  // One column more, a fraction, a negative value, 256 or NaN: the float32 kernel's business.
  cv::Mat wide(2, detail::kMaxByteColumns + 1, CV_32F, cv::Scalar(1.0f));
  EXPECT_FALSE(detail::byteNearestNeighbours(wide, wide, false, &got));
  for (float bad : {0.5f, -1.0f, 256.0f, std::numeric_limits<float>::quiet_NaN()}) {
    cv::Mat odd = byteDescriptors(20, 128, 256, 3);
    odd.at<float>(19, 127) = bad;
    EXPECT_FALSE(detail::byteNearestNeighbours(odd, r.colRange(0, 128), false, &got)) << bad;
    EXPECT_FALSE(detail::byteNearestNeighbours(r.colRange(0, 128), odd, false, &got)) << bad;
  }
}

TEST(ExactNearestNeighbours, BothKernelsGiveTheSameNeighbours) {
  // Whichever kernel exactNearestNeighbours picks, the float32 one agrees up to exact ties.
  const cv::Mat q = byteDescriptors(700, 128, 256, 11), r = byteDescriptors(900, 128, 256, 12);
  const NearestNeighbours a = exactNearestNeighbours(q, r, true);
  const NearestNeighbours b = float32NearestNeighbours(q, r, true);
  EXPECT_LE(compareNeighbours(a.forward, b.forward, 1e-3f), 7);
  ASSERT_EQ(a.reverse_nearest.size(), b.reverse_nearest.size());
  int differ = 0;
  for (size_t j = 0; j < a.reverse_nearest.size(); ++j) {
    const int i = a.reverse_nearest[j], k = b.reverse_nearest[j];
    if (i == k) continue;
    ++differ;  // only where both queries are equally near (a tie within float rounding)
    const int jj = static_cast<int>(j);
    EXPECT_NEAR(cv::norm(q.row(i), r.row(jj), cv::NORM_L2), cv::norm(q.row(k), r.row(jj), cv::NORM_L2),
                1e-3)
        << "reference " << j;
  }
  EXPECT_LE(differ, 9);
  // Real-valued descriptors always take the float32 kernel: identical results.
  const cv::Mat qr = randomDescriptors(300, 64, false, 5), rr = randomDescriptors(200, 64, false, 6);
  const NearestNeighbours c = exactNearestNeighbours(qr, rr, true);
  const NearestNeighbours d = float32NearestNeighbours(qr, rr, true);
  for (size_t i = 0; i < c.forward.size(); ++i) {
    EXPECT_EQ(c.forward[i].best, d.forward[i].best);
    EXPECT_EQ(c.forward[i].second, d.forward[i].second);
  }
  EXPECT_EQ(c.reverse_nearest, d.reverse_nearest);
  // The kernel named for reports is the one taken.
  EXPECT_EQ(exactNearestNeighboursKernel(q, r).rfind("int8", 0) == 0,
            detail::byteKernelAvailable());
  EXPECT_EQ(exactNearestNeighboursKernel(qr, rr).rfind("float32 OpenBLAS", 0), 0u);
}

TEST(ExactNearestNeighbours, MatchesTheScalarReferenceAcrossBlockBoundaries) {
  // Sizes around the blocks (256 queries, 2048 references) and the SIMD width (4).
  const std::vector<std::pair<int, int>> sizes = {{1, 1},      {1, 2},      {3, 3},   {7, 5},
                                                  {257, 2049}, {300, 2053}, {513, 11}};
  for (const auto& [nq, nr] : sizes) {
    for (bool integers : {true, false}) {
      const cv::Mat q = randomDescriptors(nq, 128, integers, 7 + nq);
      const cv::Mat r = randomDescriptors(nr, 128, integers, 11 + nr);
      const std::vector<TwoNearest> want = scalarReference(q, r);
      const NearestNeighbours got = exactNearestNeighbours(q, r, false);
      const int differ = compareNeighbours(got.forward, want, integers ? 1e-3f : 1e-2f);
      EXPECT_LE(differ, nq / 100) << nq << " x " << nr << (integers ? " integer" : " real");
    }
  }
}

TEST(ExactNearestNeighbours, ReverseNearestIsTheMutualCheckOfTheSamePass) {
  const cv::Mat q = randomDescriptors(600, 128, true, 1), r = randomDescriptors(2100, 128, true, 2);
  const NearestNeighbours got = exactNearestNeighbours(q, r, true);
  const std::vector<TwoNearest> backward = scalarReference(r, q);
  ASSERT_EQ(got.reverse_nearest.size(), 2100u);
  int differ = 0;
  for (size_t j = 0; j < backward.size(); ++j) {
    const int i = got.reverse_nearest[j];
    ASSERT_GE(i, 0);
    const float d = static_cast<float>(cv::norm(q.row(i), r.row(static_cast<int>(j)), cv::NORM_L2));
    EXPECT_NEAR(d, backward[j].best_distance, 1e-3f) << "reference " << j;
    differ += i != backward[j].best;
  }
  EXPECT_LE(differ, 21);  // exact ties only
  EXPECT_TRUE(exactNearestNeighbours(q, r, false).reverse_nearest.empty());
}

TEST(ExactNearestNeighbours, EmptyAndTinySetsAndBadTypes) {
  const cv::Mat none(0, 128, CV_32F), one = randomDescriptors(1, 128, true, 3);
  EXPECT_TRUE(exactNearestNeighbours(none, one, true).forward.empty());
  const NearestNeighbours lonely = exactNearestNeighbours(one, none, true);
  ASSERT_EQ(lonely.forward.size(), 1u);
  EXPECT_EQ(lonely.forward[0].best, -1);
  EXPECT_TRUE(lonely.reverse_nearest.empty());
  const NearestNeighbours single = exactNearestNeighbours(one, one, true);
  EXPECT_EQ(single.forward[0].best, 0);
  EXPECT_EQ(single.forward[0].best_distance, 0.0f);
  EXPECT_EQ(single.forward[0].second, -1);
  EXPECT_EQ(single.reverse_nearest, std::vector<int>{0});
  EXPECT_THROW(exactNearestNeighbours(one, randomDescriptors(1, 64, true, 4), false),
               std::invalid_argument);
  cv::Mat bytes;
  one.convertTo(bytes, CV_8U);
  EXPECT_THROW(exactNearestNeighbours(bytes, bytes, false), std::invalid_argument);
}

/// SIFT of a 640x480 synthetic pair, or of Teddy when the data is there.
std::pair<Features, Features> siftPair() {
  const std::string teddy = test::dataSet("middlebury_stereo2003_teddy");
  cv::Mat left, right;
  if (!teddy.empty()) {
    left = cv::imread(teddy + "/im2.png"), right = cv::imread(teddy + "/im6.png");
  }
  if (left.empty() || right.empty()) {
    SceneConfig scene;
    scene.width_px = 640, scene.height_px = 480;
    left = renderSceneView(scene, 0).image, right = renderSceneView(scene, 1).image;
  }
  return {detectSift(left), detectSift(right)};
}

TEST(ExactNearestNeighbours, SameNeighboursAsOpenCvBruteForceOnSift) {
  const auto [left, right] = siftPair();
  ASSERT_GT(left.descriptors.rows, 500);
  std::vector<std::vector<cv::DMatch>> bf;
  cv::BFMatcher(cv::NORM_L2).knnMatch(left.descriptors, right.descriptors, bf, 2);
  std::vector<TwoNearest> want;
  for (const auto& k : bf)
    want.push_back({k[0].trainIdx, k[1].trainIdx, k[0].distance, k[1].distance});
  const NearestNeighbours got = exactNearestNeighbours(left.descriptors, right.descriptors, true);
  const int differ = compareNeighbours(got.forward, want, 1e-2f);
  std::cout << differ << " of " << want.size() << " nearest neighbours differ from BFMatcher's "
            << "(exact ties)\n";
  EXPECT_LE(differ, static_cast<int>(want.size()) / 1000);
}

TEST(ExactNearestNeighbours, BlasBackendKeepsTheBruteForceMatches) {
  const auto [left, right] = siftPair();
  for (bool cross_check : {false, true}) {
    MatchConfig config;
    config.cross_check = cross_check;
    config.backend = "brute-force";
    const std::vector<cv::DMatch> bf =
        matchDescriptors(left.descriptors, right.descriptors, config);
    config.backend = "blas";
    const std::vector<cv::DMatch> blas =
        matchDescriptors(left.descriptors, right.descriptors, config);
    std::set<std::pair<int, int>> a, b;
    for (const cv::DMatch& m : bf) a.emplace(m.queryIdx, m.trainIdx);
    for (const cv::DMatch& m : blas) b.emplace(m.queryIdx, m.trainIdx);
    size_t shared = 0;
    for (const auto& pair : b) shared += a.count(pair);
    std::cout << "cross_check " << cross_check << ": " << shared << " of " << a.size()
              << " BFMatcher matches, " << b.size() << " by blas\n";
    EXPECT_GE(shared + a.size() / 1000, a.size());
    EXPECT_GE(shared + b.size() / 1000, b.size());
  }
}

}  // namespace
}  // namespace sift_hull
