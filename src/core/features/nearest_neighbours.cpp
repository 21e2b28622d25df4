#include "sift_hull/features/nearest_neighbours.h"

#include <cblas.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <mutex>
#include <opencv2/core/hal/intrin.hpp>
#include <stdexcept>
#include <thread>

#include "common/parallel.h"
#include "features/neighbour_kernels.h"

namespace sift_hull {
namespace {

constexpr float kInf = std::numeric_limits<float>::infinity();
/// Block sizes: a block of squared distances is kQueryBlock x kReferenceBlock floats (2 MB).
constexpr int kQueryBlock = 256;
constexpr int kReferenceBlock = 2048;

/// Rows [q, 1, ||q||^2] of the queries and [-2 r, ||r||^2, 1] of the references: their dot product
/// is the squared distance, so one matrix product gives a block of squared distances.
cv::Mat augmented(const cv::Mat& descriptors, bool reference) {
  const int d = descriptors.cols;
  cv::Mat rows(descriptors.rows, d + 2, CV_32F);
  for (int i = 0; i < descriptors.rows; ++i) {
    const float* in = descriptors.ptr<float>(i);
    float* out = rows.ptr<float>(i);
    float norm2 = 0.0f;
    for (int k = 0; k < d; ++k) norm2 += in[k] * in[k];
    for (int k = 0; k < d; ++k) out[k] = reference ? -2.0f * in[k] : in[k];
    out[d] = reference ? norm2 : 1.0f;
    out[d + 1] = reference ? 1.0f : norm2;
  }
  return rows;
}

/// A query's running two nearest over the reference blocks seen so far (squared distances).
struct Running {
  float best = kInf, second = kInf;
  int best_index = -1, second_index = -1;
  void offer(float value, int index) {
    if (value < best) {
      second = best, second_index = best_index, best = value, best_index = index;
    } else if (value < second) {
      second = value, second_index = index;
    }
  }
};

/// Folds one row of squared distances (references first..first+n-1) into the query's running two
/// nearest; with `reverse`, also each reference's nearest query so far.
void scanRow(const float* row, int n, int first, int query, Running* running, float* reverse_best,
             int* reverse_index) {
  int j = 0;
#if CV_SIMD128
  constexpr int kLanes = cv::v_float32x4::nlanes;
  if (n >= kLanes) {
    cv::v_float32x4 best = cv::v_setall_f32(kInf), second = best;
    cv::v_int32x4 best_index = cv::v_setall_s32(-1), second_index = best_index;
    cv::v_int32x4 index(first, first + 1, first + 2, first + 3);
    const cv::v_int32x4 step = cv::v_setall_s32(kLanes), query_v = cv::v_setall_s32(query);
    for (; j + kLanes <= n; j += kLanes, index += step) {
      const cv::v_float32x4 v = cv::v_load(row + j);
      const cv::v_float32x4 below_best = v < best, below_second = v < second;
      const cv::v_int32x4 m1 = cv::v_reinterpret_as_s32(below_best);
      const cv::v_int32x4 m2 = cv::v_reinterpret_as_s32(below_second);
      second_index = cv::v_select(m1, best_index, cv::v_select(m2, index, second_index));
      second = cv::v_select(below_best, best, cv::v_select(below_second, v, second));
      best_index = cv::v_select(m1, index, best_index);
      best = cv::v_select(below_best, v, best);
      if (reverse_best) {
        const cv::v_float32x4 r = cv::v_load(reverse_best + j);
        const cv::v_float32x4 closer = v < r;
        cv::v_store(reverse_best + j, cv::v_select(closer, v, r));
        const cv::v_int32x4 ri = cv::v_load(reverse_index + j);
        cv::v_store(reverse_index + j, cv::v_select(cv::v_reinterpret_as_s32(closer), query_v, ri));
      }
    }
    float lane_value[2][kLanes];
    int lane_index[2][kLanes];
    cv::v_store(lane_value[0], best), cv::v_store(lane_value[1], second);
    cv::v_store(lane_index[0], best_index), cv::v_store(lane_index[1], second_index);
    // Among exactly equal distances the index kept depends on the lane order: ties are ties.
    for (int lane = 0; lane < kLanes; ++lane) {
      for (int k = 0; k < 2; ++k) {
        if (lane_index[k][lane] >= 0) running->offer(lane_value[k][lane], lane_index[k][lane]);
      }
    }
  }
#endif
  for (; j < n; ++j) {
    running->offer(row[j], first + j);
    if (reverse_best && row[j] < reverse_best[j])
      reverse_best[j] = row[j], reverse_index[j] = query;
  }
}

/// Each reference's nearest query among one thread's queries (squared distance, index).
struct Reverse {
  explicit Reverse(int references) : best(references, kInf), index(references, -1) {}
  std::vector<float> best;
  std::vector<int> index;
};

/// One block of queries against every reference block: a matrix product, then the scans.
void scanQueryBlock(const cv::Mat& q, const cv::Mat& r, int q0, std::vector<float>* block,
                    Running* running, Reverse* reverse) {
  const int bq = std::min(kQueryBlock, q.rows - q0), d = q.cols;
  for (int r0 = 0; r0 < r.rows; r0 += kReferenceBlock) {
    const int br = std::min(kReferenceBlock, r.rows - r0);
    cblas_sgemm(CblasRowMajor, CblasNoTrans, CblasTrans, bq, br, d, 1.0f, q.ptr<float>(q0), d,
                r.ptr<float>(r0), d, 0.0f, block->data(), br);
    for (int i = 0; i < bq; ++i) {
      scanRow(block->data() + static_cast<size_t>(i) * br, br, r0, q0 + i, &running[q0 + i],
              reverse ? reverse->best.data() + r0 : nullptr,
              reverse ? reverse->index.data() + r0 : nullptr);
    }
  }
}

/// The threads' nearest queries merged: the smallest distance, the lower index among equals.
std::vector<int> mergeReverse(const std::vector<Reverse>& parts) {
  std::vector<int> nearest(parts.front().index);
  std::vector<float> best(parts.front().best);
  for (size_t t = 1; t < parts.size(); ++t) {
    for (size_t j = 0; j < nearest.size(); ++j) {
      const float v = parts[t].best[j];
      const int i = parts[t].index[j];
      if (i >= 0 && (v < best[j] || (v == best[j] && i < nearest[j]) || nearest[j] < 0)) {
        best[j] = v, nearest[j] = i;
      }
    }
  }
  return nearest;
}

float l2(const cv::Mat& a, int i, const cv::Mat& b, int j) {
  return static_cast<float>(cv::norm(a.row(i), b.row(j), cv::NORM_L2));
}

/// The reported pair: distances recomputed directly, ordered by them.
TwoNearest finish(const Running& running, const cv::Mat& queries, int query,
                  const cv::Mat& references) {
  TwoNearest result{running.best_index, running.second_index, kInf, kInf};
  if (result.best >= 0) result.best_distance = l2(queries, query, references, result.best);
  if (result.second >= 0) result.second_distance = l2(queries, query, references, result.second);
  if (result.second >= 0 && result.second_distance < result.best_distance) {
    std::swap(result.best, result.second);
    std::swap(result.best_distance, result.second_distance);
  }
  return result;
}

/// Empty sets answer without a kernel; anything but two CV_32F matrices of equal columns throws.
bool checkedTrivial(const cv::Mat& queries, const cv::Mat& references, bool with_reverse,
                    NearestNeighbours* result) {
  if (queries.rows == 0 || references.rows == 0) {
    result->forward.assign(static_cast<size_t>(queries.rows), TwoNearest{-1, -1, kInf, kInf});
    if (with_reverse) result->reverse_nearest.assign(static_cast<size_t>(references.rows), -1);
    return true;
  }
  if (queries.type() != CV_32F || references.type() != CV_32F || queries.cols != references.cols ||
      queries.dims != 2 || references.dims != 2) {
    throw std::invalid_argument(
        "exactNearestNeighbours: descriptors must be CV_32F, equal columns");
  }
  return false;
}

}  // namespace

NearestNeighbours float32NearestNeighbours(const cv::Mat& queries, const cv::Mat& references,
                                         bool with_reverse) {
  NearestNeighbours result;
  if (checkedTrivial(queries, references, with_reverse, &result)) return result;
  // OpenBLAS's own threads would spin between calls and compete with the caller's work (SIFT of
  // the next image): one BLAS thread per call, the blocks on threads of ours.
  static std::once_flag single_threaded_blas;
  std::call_once(single_threaded_blas, [] { openblas_set_num_threads(1); });
  const cv::Mat q = augmented(queries, false), r = augmented(references, true);
  const int nq = q.rows, nr = r.rows;
  std::vector<Running> running(static_cast<size_t>(nq));
  const int blocks = (nq + kQueryBlock - 1) / kQueryBlock;
  const int threads = std::max(1, std::min<int>(std::thread::hardware_concurrency(), blocks));
  std::vector<Reverse> reverse(with_reverse ? threads : 0, Reverse(nr));
  // Query blocks are dealt to the threads in turn, so that thread t sees its queries in order.
  detail::parallelFor(static_cast<size_t>(threads), threads, [&](size_t t) {
    std::vector<float> block(static_cast<size_t>(kQueryBlock) * kReferenceBlock);
    for (int b = static_cast<int>(t); b < blocks; b += threads) {
      scanQueryBlock(q, r, b * kQueryBlock, &block, running.data(),
                     with_reverse ? &reverse[t] : nullptr);
    }
  });
  if (with_reverse) result.reverse_nearest = mergeReverse(reverse);
  result.forward.reserve(static_cast<size_t>(nq));
  for (int i = 0; i < nq; ++i) result.forward.push_back(finish(running[i], queries, i, references));
  return result;
}

NearestNeighbours exactNearestNeighbours(const cv::Mat& queries, const cv::Mat& references,
                                         bool with_reverse) {
  NearestNeighbours result;
  if (checkedTrivial(queries, references, with_reverse, &result)) return result;
  detail::ExactNeighbours exact;
  if (!detail::byteNearestNeighbours(queries, references, with_reverse, &exact)) {
    return float32NearestNeighbours(queries, references, with_reverse);
  }
  // The kernel's squared distances are exact integers: their square roots are what a direct
  // recomputation would give.
  const auto root = [](int32_t squared) {
    return squared < 0 ? kInf : static_cast<float>(std::sqrt(static_cast<double>(squared)));
  };
  result.reverse_nearest = std::move(exact.reverse);
  result.forward.reserve(static_cast<size_t>(queries.rows));
  for (size_t i = 0; i < static_cast<size_t>(queries.rows); ++i) {
    result.forward.push_back({exact.best[i], exact.second[i], root(exact.best_squared[i]),
                              root(exact.second_squared[i])});
  }
  return result;
}

std::string exactNearestNeighboursKernel(const cv::Mat& queries, const cv::Mat& references) {
  if (detail::byteKernelFits(queries, references) && detail::holdsBytes(queries) &&
      detail::holdsBytes(references)) {
    return "int8 AVX-512 VNNI";
  }
  return std::string("float32 OpenBLAS sgemm (") + openblas_get_corename() + " kernels)";
}

}  // namespace sift_hull
