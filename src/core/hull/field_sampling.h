#pragma once

#include <cstddef>
#include <vector>

#include "sift_hull/hull/hull_view.h"

namespace sift_hull {
namespace detail {

/// f_iso = max_i D_i at points (local frame, structure of arrays) into `values`, on `threads`
/// threads. The points are grouped in cubic tiles of edge `tile_edge` (local units); in a tile,
/// a view whose distance at the tile's centre plus its reach over the tile (HullView::ballBound)
/// lies below another view's distance minus that view's reach cannot hold the maximum at any
/// point of the tile, and is not looked up there. The result is the maximum over every view
/// wherever the views' reach bounds hold (as carving assumes).
void sampleMaxField(const std::vector<HullView>& views, const std::vector<float>& x,
                    const std::vector<float>& y, const std::vector<float>& z, double tile_edge,
                    int threads, float* values);

}  // namespace detail
}  // namespace sift_hull
