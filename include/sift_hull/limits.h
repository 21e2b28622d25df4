#pragma once

#include <cstddef>
#include <stdexcept>
#include <string>

// Limits on what one input may ask of the package, so that no value that parses (a parameter, a
// command-line option, a header field) can exhaust memory, overflow an integer or start more
// threads than the system has. Each is checked where the value enters, and the error names the
// limit. docs/RELIABILITY.md lists them with what they guard.

namespace sift_hull {
namespace limits {

/// Octree levels (HullConfig::max_depth): each level multiplies the surface cells by about 4;
/// depth 9 peaks near 0.9 GiB on dino with its OctoMap, so 10 stays within a few GiB.
constexpr int kMaxHullDepth = 10;
/// Threads of one computation (HullConfig::threads, the filters' threads).
constexpr int kMaxThreads = 256;
/// GMS grid cells per image side (GmsConfig::grid_cells); the paper uses 20.
constexpr int kMaxGmsGridCells = 1000;
/// Radius of a morphology disc (SilhouetteConfig::dilate_px / erode_px), pixels.
constexpr int kMaxMorphologyRadiusPx = 1000;
/// Padding of a distance map (HullConfig::padding_px), pixels.
constexpr int kMaxPaddingPx = 1000;
/// SIFT scales per octave (SiftConfig::octave_layers); OpenCV's default is 3.
constexpr int kMaxOctaveLayers = 32;
/// The default of SiftConfig::max_image_pixels: 25 megapixels (a 6000x4000 photo). SIFT needs
/// about 75 bytes per pixel of an image pair.
constexpr size_t kDefaultMaxImagePixels = 25000000;
/// Pixels of an image file the command-line program decodes (OPENCV_IO_MAX_IMAGE_PIXELS) and of
/// an image message a node accepts (a mask of 1e8 pixels is 100 MB, its distance maps 800 MB).
constexpr size_t kMaxDecodedImagePixels = 100000000;
/// Width or height of an image or map read from a file or a message, pixels.
constexpr size_t kMaxImageSidePx = 1 << 16;

/// Views (or cameras) of one calibration file: par count lines, COLMAP models, LLFF poses.
constexpr size_t kMaxCalibrationViews = 1000000;
/// Characters of an image name in a binary calibration file (COLMAP images.bin).
constexpr size_t kMaxImageNameChars = 4096;
/// Bytes of a .npy header (LLFF poses_bounds.npy); numpy writes well under 200.
constexpr size_t kMaxNpyHeaderBytes = 65536;
/// Decompressed bytes of one .npy entry of an .npz archive (IDR cameras.npz), checked before it is
/// allocated: a 4x4 float64 array takes 256 bytes, so a deflate bomb stops here.
constexpr size_t kMaxNpzEntryBytes = 1 << 20;
/// Entries of an .npz archive: IDR and NeuS write six arrays per view.
constexpr size_t kMaxNpzEntries = 16 * kMaxCalibrationViews;

/// Throws std::invalid_argument "`name` must be in [low, high], got value" when out of range.
inline void requireInRange(const std::string& name, long long value, long long low,
                           long long high) {
  if (value < low || value > high) {
    throw std::invalid_argument(name + " must be in [" + std::to_string(low) + ", " +
                                std::to_string(high) + "], got " + std::to_string(value));
  }
}

}  // namespace limits
}  // namespace sift_hull
