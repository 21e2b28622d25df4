#pragma once

// What the COLMAP readers share: the camera models, and cameras and views made from a model's
// fields (colmap.cpp); the text model's readers (colmap_text.cpp).

#include <cstdint>
#include <map>
#include <string>
#include <vector>

#include "sift_hull/io/colmap.h"

namespace sift_hull {
namespace colmap_detail {

struct ModelInfo {
  int id;
  const char* name;
  int params;
  bool supported;
};

const ModelInfo* modelById(int64_t id);
const ModelInfo* modelByName(const std::string& name);

/// Intrinsics from a model's parameters (COLMAP's order), or a ParseError at (file, line).
/// `source` says where the camera is written (ColmapCamera::source).
ColmapCamera makeCamera(const ModelInfo& model, uint64_t width, uint64_t height,
                        const std::vector<double>& p, const std::string& file, int line,
                        const std::string& source);

/// A view from an image's pose; throws ParseError at (file, line) for a bad pose or camera id.
CalibratedView makeView(const std::string& name, const double q[4], const double t[3],
                        uint32_t camera_id, const std::map<uint32_t, ColmapCamera>& cameras,
                        const std::string& file, int line, const std::string& source);

/// cameras.txt.
std::map<uint32_t, ColmapCamera> readCamerasText(const std::string& file);

/// images.txt, the views in the file's order. Each image line may be followed by its POINTS2D
/// line (COLMAP writes one, empty for an image without points) or not (some exporters leave it
/// out); the points are checked as they are read and not kept.
std::vector<CalibratedView> readImagesText(const std::string& file,
                                           const std::map<uint32_t, ColmapCamera>& cameras);

}  // namespace colmap_detail
}  // namespace sift_hull
