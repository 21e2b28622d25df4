#include "hull/field_sampling.h"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>
#include <numeric>

#include "common/parallel.h"

namespace sift_hull {
namespace detail {
namespace {

/// Tile coordinates packed into one key, 21 bits per axis (clamped).
uint64_t tileKey(float x, float y, float z, double tile_edge) {
  const auto coordinate = [tile_edge](float value) {
    const double cell = std::floor((static_cast<double>(value) + 2.0) / tile_edge);
    return static_cast<uint64_t>(std::clamp(cell, 0.0, 2097151.0));
  };
  return coordinate(x) | coordinate(y) << 21 | coordinate(z) << 42;
}

/// The centre of a tile, from its key.
void tileCentre(uint64_t key, double tile_edge, float* centre) {
  for (int axis = 0; axis < 3; ++axis) {
    const double cell = static_cast<double>((key >> (21 * axis)) & 2097151u);
    centre[axis] = static_cast<float>((cell + 0.5) * tile_edge - 2.0);
  }
}

}  // namespace

void sampleMaxField(const std::vector<HullView>& views, const std::vector<float>& x,
                    const std::vector<float>& y, const std::vector<float>& z, double tile_edge,
                    int threads, float* values) {
  const size_t count = x.size();
  std::vector<uint64_t> keys(count);
  for (size_t i = 0; i < count; ++i) keys[i] = tileKey(x[i], y[i], z[i], tile_edge);
  std::vector<uint32_t> order(count);
  std::iota(order.begin(), order.end(), 0u);
  std::sort(order.begin(), order.end(), [&](uint32_t a, uint32_t b) { return keys[a] < keys[b]; });
  std::vector<size_t> starts;  // the first point (in `order`) of each tile
  for (size_t i = 0; i < count; ++i) {
    if (i == 0 || keys[order[i]] != keys[order[i - 1]]) starts.push_back(i);
  }
  starts.push_back(count);
  const float radius = static_cast<float>(0.5 * std::sqrt(3.0) * tile_edge);
  parallelFor(starts.size() - 1, threads, [&](size_t tile) {
    const size_t begin = starts[tile], end = starts[tile + 1], n = end - begin;
    float centre[3];
    tileCentre(keys[order[begin]], tile_edge, centre);
    std::vector<float> upper(views.size());
    float lower = -std::numeric_limits<float>::infinity();
    for (size_t v = 0; v < views.size(); ++v) {
      float value = 0.0f, reach = 0.0f;
      views[v].ballBound(centre[0], centre[1], centre[2], radius, &value, &reach);
      upper[v] = value + reach;
      lower = std::max(lower, value - reach);
    }
    std::vector<float> px(n), py(n), pz(n), out(n, -HullView::kFarOutside_px);
    for (size_t i = 0; i < n; ++i) {
      const uint32_t p = order[begin + i];
      px[i] = x[p], py[i] = y[p], pz[i] = z[p];
    }
    for (size_t v = 0; v < views.size(); ++v) {
      if (!(upper[v] >= lower)) continue;  // below another view everywhere in the tile
      views[v].maxInto({px.data(), py.data(), pz.data(), n}, out.data());
    }
    for (size_t i = 0; i < n; ++i) values[order[begin + i]] = out[i];
  });
}

}  // namespace detail
}  // namespace sift_hull
