#include "features/neighbour_kernels.h"

#include <algorithm>
#include <cstdint>
#include <cstdlib>
#include <limits>
#include <memory>
#include <new>
#include <thread>

#include "common/parallel.h"

#if defined(__x86_64__)
#include <immintrin.h>
#endif

namespace sift_hull {
namespace detail {

#if defined(__x86_64__)
namespace {

// Layout. A "panel" is 16 references; for each group of 4 descriptor columns it holds one
// 64-byte vector: 4 unsigned bytes of each of its 16 references. A query row holds its bytes
// minus 128 as signed bytes, so that vpdpbusd (unsigned x signed, 4 products per int32 lane)
// gives acc = sum r (q - 128) = r.q - 128 sum(r). With c_j = ||r_j||^2 - 256 sum(r_j), the
// squared distance is ||q||^2 + c_j - 2 acc: exact in int32 (at most 1024 x 255^2 x 2 < 2^31).
constexpr int kLanes = 16;
constexpr int kPanelBytes = 64;           // per group of 4 columns
constexpr int32_t kFar = int32_t{1} << 29;  // padding: farther than any real distance
constexpr int kTileQueries = 4;           // queries of one register tile
constexpr int kTilePanels = 4;            // panels of one register tile (16 accumulators)
constexpr int kBlockQueries = 64;         // queries whose running state one thread keeps
constexpr int kChunkPanels = 32;          // 512 references (64 KB for SIFT) swept per tile
static_assert(kChunkPanels % kTilePanels == 0 && kBlockQueries % kTileQueries == 0);

struct FreeDeleter {
  void operator()(void* p) const { std::free(p); }
};
template <typename T>
using Aligned = std::unique_ptr<T[], FreeDeleter>;

template <typename T>
Aligned<T> alignedArray(size_t count) {
  const size_t bytes = (count * sizeof(T) + 63) / 64 * 64;
  void* p = std::aligned_alloc(64, std::max<size_t>(bytes, 64));
  if (!p) throw std::bad_alloc();
  return Aligned<T>(static_cast<T*>(p));
}

/// The value as a byte, or -1 when it is not an integer in [0, 255] (NaN included).
inline int asByte(float v) {
  if (!(v >= 0.0f && v <= 255.0f)) return -1;
  const int b = static_cast<int>(v);
  return static_cast<float>(b) == v ? b : -1;
}

struct PackedReferences {
  int panels = 0, groups = 0;
  Aligned<uint8_t> bytes;  // panels x groups x 64
  Aligned<int32_t> c;      // panels x 16: ||r||^2 - 256 sum(r), kFar for padding
};

struct PackedQueries {
  int groups = 0;
  Aligned<int8_t> bytes;   // rows (padded to a whole tile) x groups x 4
  Aligned<int32_t> norm2;  // per row: ||q||^2, kFar for padding
};

bool packReferences(const cv::Mat& r, PackedReferences* out) {
  // Panels padded to whole tiles (padding references have c = kFar, and are never chosen).
  const int d = r.cols, groups = (d + 3) / 4;
  const int panels = (r.rows + kLanes * kTilePanels - 1) / (kLanes * kTilePanels) * kTilePanels;
  out->panels = panels, out->groups = groups;
  out->bytes = alignedArray<uint8_t>(static_cast<size_t>(panels) * groups * kPanelBytes);
  out->c = alignedArray<int32_t>(static_cast<size_t>(panels) * kLanes);
  std::fill_n(out->bytes.get(), static_cast<size_t>(panels) * groups * kPanelBytes, uint8_t{0});
  std::fill_n(out->c.get(), static_cast<size_t>(panels) * kLanes, kFar);
  for (int j = 0; j < r.rows; ++j) {
    const float* row = r.ptr<float>(j);
    uint8_t* panel = out->bytes.get() + static_cast<size_t>(j / kLanes) * groups * kPanelBytes;
    const int lane = j % kLanes;
    int32_t norm2 = 0, sum = 0;
    for (int k = 0; k < d; ++k) {
      const int b = asByte(row[k]);
      if (b < 0) return false;
      norm2 += b * b, sum += b;
      panel[(k / 4) * kPanelBytes + lane * 4 + k % 4] = static_cast<uint8_t>(b);
    }
    out->c[j] = norm2 - 256 * sum;
  }
  return true;
}

bool packQueries(const cv::Mat& q, PackedQueries* out) {
  const int d = q.cols, groups = (d + 3) / 4;
  const int rows = (q.rows + kTileQueries - 1) / kTileQueries * kTileQueries;
  out->groups = groups;
  out->bytes = alignedArray<int8_t>(static_cast<size_t>(rows) * groups * 4);
  out->norm2 = alignedArray<int32_t>(static_cast<size_t>(rows));
  std::fill_n(out->bytes.get(), static_cast<size_t>(rows) * groups * 4, int8_t{0});
  std::fill_n(out->norm2.get(), static_cast<size_t>(rows), kFar);
  for (int i = 0; i < q.rows; ++i) {
    const float* row = q.ptr<float>(i);
    int8_t* packed = out->bytes.get() + static_cast<size_t>(i) * groups * 4;
    int32_t norm2 = 0;
    for (int k = 0; k < d; ++k) {
      const int b = asByte(row[k]);
      if (b < 0) return false;
      norm2 += b * b;
      packed[k] = static_cast<int8_t>(b - 128);
    }
    out->norm2[i] = norm2;
  }
  return true;
}

/// Per query of a block, per lane: the two smallest (distance - ||q||^2) seen and their indices.
struct ForwardState {
  alignas(64) int32_t best[kBlockQueries][kLanes], second[kBlockQueries][kLanes];
  alignas(64) int32_t best_index[kBlockQueries][kLanes], second_index[kBlockQueries][kLanes];
};

/// Per reference: its nearest query among one thread's queries (squared distance, index).
struct ReverseState {
  explicit ReverseState(int panels)
      : best(alignedArray<int32_t>(static_cast<size_t>(panels) * kLanes)),
        index(alignedArray<int32_t>(static_cast<size_t>(panels) * kLanes)) {
    std::fill_n(best.get(), static_cast<size_t>(panels) * kLanes,
                std::numeric_limits<int32_t>::max());
    std::fill_n(index.get(), static_cast<size_t>(panels) * kLanes, -1);
  }
  Aligned<int32_t> best, index;
};

/// Sixteen int32 lanes as a gcc vector.
using V16 = int32_t __attribute__((vector_size(64)));

#define SIFT_HULL_VNNI __attribute__((target("avx512f,avx512bw,avx512vnni")))

/// One tile: kTileQueries queries (from `query`, rows of the block from `row`) against the
/// kTilePanels panels from `panel`; folds the distances into the forward and reverse states.
SIFT_HULL_VNNI void tile(const PackedQueries& q, const PackedReferences& r, int query, int row,
                         int panel, ForwardState* forward, ReverseState* reverse) {
  const int groups = q.groups;
  __m512i acc[kTileQueries][kTilePanels];
  for (auto& a : acc)
    for (auto& v : a) v = _mm512_setzero_si512();
  const int8_t* qrow = q.bytes.get() + static_cast<size_t>(query) * groups * 4;
  const uint8_t* rp = r.bytes.get() + static_cast<size_t>(panel) * groups * kPanelBytes;
  for (int g = 0; g < groups; ++g) {
    __m512i refs[kTilePanels];
    for (int c = 0; c < kTilePanels; ++c)
      refs[c] = _mm512_load_si512(rp + (static_cast<size_t>(c) * groups + g) * kPanelBytes);
    for (int i = 0; i < kTileQueries; ++i) {
      int32_t four;
      __builtin_memcpy(&four, qrow + (static_cast<size_t>(i) * groups + g) * 4, 4);
      const __m512i b = _mm512_set1_epi32(four);
      for (int c = 0; c < kTilePanels; ++c) acc[i][c] = _mm512_dpbusd_epi32(acc[i][c], refs[c], b);
    }
  }
  __m512i c_of[kTilePanels], rbest[kTilePanels], rindex[kTilePanels], index[kTilePanels];
  const __m512i lane = _mm512_set_epi32(15, 14, 13, 12, 11, 10, 9, 8, 7, 6, 5, 4, 3, 2, 1, 0);
  for (int c = 0; c < kTilePanels; ++c) {
    const size_t at = static_cast<size_t>(panel + c) * kLanes;
    c_of[c] = _mm512_load_si512(r.c.get() + at);
    index[c] = _mm512_add_epi32(lane, _mm512_set1_epi32(static_cast<int>(at)));
    if (reverse) {
      rbest[c] = _mm512_load_si512(reverse->best.get() + at);
      rindex[c] = _mm512_load_si512(reverse->index.get() + at);
    }
  }
  for (int i = 0; i < kTileQueries; ++i) {
    const int s = row + i;
    __m512i b1 = _mm512_load_si512(forward->best[s]), b2 = _mm512_load_si512(forward->second[s]);
    __m512i i1 = _mm512_load_si512(forward->best_index[s]);
    __m512i i2 = _mm512_load_si512(forward->second_index[s]);
    const __m512i norm2 = _mm512_set1_epi32(q.norm2[query + i]);
    const __m512i who = _mm512_set1_epi32(query + i);
    for (int c = 0; c < kTilePanels; ++c) {
      // Plain vector arithmetic where gcc 12's intrinsics warn about their undefined passthrough.
      const V16 a = reinterpret_cast<V16>(acc[i][c]);
      const V16 e = reinterpret_cast<V16>(c_of[c]) - (a + a);
      const __m512i em = reinterpret_cast<__m512i>(e);
      const __mmask16 below_best = _mm512_cmplt_epi32_mask(em, b1);
      const __mmask16 below_second = _mm512_cmplt_epi32_mask(em, b2);
      i2 = _mm512_mask_mov_epi32(i2, below_second, index[c]);
      i2 = _mm512_mask_mov_epi32(i2, below_best, i1);
      i1 = _mm512_mask_mov_epi32(i1, below_best, index[c]);
      b2 = _mm512_mask_mov_epi32(b2, below_second, _mm512_mask_mov_epi32(em, below_best, b1));
      b1 = _mm512_mask_mov_epi32(b1, below_best, em);
      if (reverse) {
        const __m512i full = reinterpret_cast<__m512i>(e + reinterpret_cast<V16>(norm2));
        const __mmask16 closer = _mm512_cmplt_epi32_mask(full, rbest[c]);
        rbest[c] = _mm512_mask_mov_epi32(rbest[c], closer, full);
        rindex[c] = _mm512_mask_mov_epi32(rindex[c], closer, who);
      }
    }
    _mm512_store_si512(forward->best[s], b1), _mm512_store_si512(forward->second[s], b2);
    _mm512_store_si512(forward->best_index[s], i1);
    _mm512_store_si512(forward->second_index[s], i2);
  }
  if (reverse) {
    for (int c = 0; c < kTilePanels; ++c) {
      const size_t at = static_cast<size_t>(panel + c) * kLanes;
      _mm512_store_si512(reverse->best.get() + at, rbest[c]);
      _mm512_store_si512(reverse->index.get() + at, rindex[c]);
    }
  }
}

/// A query's two nearest from its 16 lanes: smallest distance first, the lower index among
/// equals; padding references (kFar and beyond) are never chosen.
void reduceLanes(const ForwardState& state, int s, int32_t norm2, ExactNeighbours* out, int query) {
  struct Candidate {
    int32_t value;
    int32_t index;
    bool operator<(const Candidate& o) const {
      return value != o.value ? value < o.value : index < o.index;
    }
  };
  Candidate first{kFar, -1}, next{kFar, -1};
  const auto offer = [&](Candidate c) {
    if (c.index < 0 || c.value >= kFar) return;
    if (c < first || first.index < 0) {
      next = first, first = c;
    } else if (c < next || next.index < 0) {
      next = c;
    }
  };
  for (int l = 0; l < kLanes; ++l) {
    offer({state.best[s][l], state.best_index[s][l]});
    offer({state.second[s][l], state.second_index[s][l]});
  }
  out->best[query] = first.index, out->second[query] = next.index;
  // The lanes hold distance - ||q||^2: the squared distances are exact integers.
  out->best_squared[query] = first.index >= 0 ? first.value + norm2 : -1;
  out->second_squared[query] = next.index >= 0 ? next.value + norm2 : -1;
}

void initialise(ForwardState* state) {
  for (int s = 0; s < kBlockQueries; ++s) {
    std::fill_n(state->best[s], kLanes, std::numeric_limits<int32_t>::max());
    std::fill_n(state->second[s], kLanes, std::numeric_limits<int32_t>::max());
    std::fill_n(state->best_index[s], kLanes, -1);
    std::fill_n(state->second_index[s], kLanes, -1);
  }
}

/// One block of queries against every reference: chunks of panels, each swept by every tile.
void scanBlock(const PackedQueries& q, const PackedReferences& r, int first, int count,
               ForwardState* state, ReverseState* reverse, ExactNeighbours* out) {
  initialise(state);
  const int tiles = (count + kTileQueries - 1) / kTileQueries;
  for (int p0 = 0; p0 < r.panels; p0 += kChunkPanels) {
    const int p1 = std::min(r.panels, p0 + kChunkPanels);
    for (int t = 0; t < tiles; ++t) {
      for (int p = p0; p < p1; p += kTilePanels) {
        tile(q, r, first + t * kTileQueries, t * kTileQueries, p, state, reverse);
      }
    }
  }
  for (int s = 0; s < count; ++s) {
    reduceLanes(*state, s, q.norm2[first + s], out, first + s);
  }
}

}  // namespace

bool byteKernelAvailable() {
  static const bool available = __builtin_cpu_supports("avx512f") &&
                                __builtin_cpu_supports("avx512bw") &&
                                __builtin_cpu_supports("avx512vnni");
  return available;
}

bool byteKernelFits(const cv::Mat& queries, const cv::Mat& references) {
  return byteKernelAvailable() && queries.type() == CV_32F && references.type() == CV_32F &&
         queries.dims == 2 && references.dims == 2 && queries.cols == references.cols &&
         queries.cols >= 1 && queries.cols <= kMaxByteColumns && queries.rows >= 1 &&
         references.rows >= 1;
}

bool holdsBytes(const cv::Mat& descriptors) {
  for (int i = 0; i < descriptors.rows; ++i) {
    const float* row = descriptors.ptr<float>(i);
    for (int k = 0; k < descriptors.cols; ++k) {
      if (asByte(row[k]) < 0) return false;
    }
  }
  return true;
}

bool byteNearestNeighbours(const cv::Mat& queries, const cv::Mat& references, bool with_reverse,
                           ExactNeighbours* out) {
  if (!byteKernelFits(queries, references)) return false;
  PackedQueries q;
  PackedReferences r;
  if (!packReferences(references, &r) || !packQueries(queries, &q)) return false;
  const int nq = queries.rows;
  out->best.assign(static_cast<size_t>(nq), -1);
  out->second.assign(static_cast<size_t>(nq), -1);
  out->best_squared.assign(static_cast<size_t>(nq), -1);
  out->second_squared.assign(static_cast<size_t>(nq), -1);
  const int blocks = (nq + kBlockQueries - 1) / kBlockQueries;
  const int threads = std::max(1, std::min<int>(std::thread::hardware_concurrency(), blocks));
  std::vector<ReverseState> reverse;
  if (with_reverse) reverse.reserve(static_cast<size_t>(threads));
  for (int t = 0; with_reverse && t < threads; ++t) reverse.emplace_back(r.panels);
  // Blocks are dealt to the threads in turn, so that each thread sees its queries in order and
  // keeps the lowest index among equally near queries.
  parallelFor(static_cast<size_t>(threads), threads, [&](size_t t) {
    const auto state = std::make_unique<ForwardState>();
    for (int b = static_cast<int>(t); b < blocks; b += threads) {
      const int first = b * kBlockQueries;
      scanBlock(q, r, first, std::min(kBlockQueries, nq - first), state.get(),
                with_reverse ? &reverse[t] : nullptr, out);
    }
  });
  if (with_reverse) {
    out->reverse.assign(static_cast<size_t>(references.rows), -1);
    for (int j = 0; j < references.rows; ++j) {
      int32_t best = std::numeric_limits<int32_t>::max();
      for (const ReverseState& part : reverse) {
        const int32_t v = part.best[j], i = part.index[j];
        if (i >= 0 && (v < best || (v == best && i < out->reverse[j]))) {
          best = v, out->reverse[j] = i;
        }
      }
    }
  } else {
    out->reverse.clear();
  }
  return true;
}

#else  // not x86-64: the float32 path serves every descriptor

bool byteKernelAvailable() { return false; }

bool byteKernelFits(const cv::Mat&, const cv::Mat&) { return false; }

bool holdsBytes(const cv::Mat&) { return false; }

bool byteNearestNeighbours(const cv::Mat&, const cv::Mat&, bool, ExactNeighbours*) {
  return false;
}

#endif

}  // namespace detail
}  // namespace sift_hull
