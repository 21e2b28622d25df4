#include "synthetic/texture.h"

#include <algorithm>
#include <cmath>
#include <cstdint>

namespace sift_hull {
namespace {

uint32_t hash(int32_t x, int32_t y, int32_t z, uint32_t seed) {
  uint32_t h = seed * 0x9E3779B9u;
  h ^= static_cast<uint32_t>(x) * 0x85EBCA6Bu;
  h = (h ^ (h >> 13)) * 0xC2B2AE35u;
  h ^= static_cast<uint32_t>(y) * 0x27D4EB2Fu;
  h = (h ^ (h >> 15)) * 0x165667B1u;
  h ^= static_cast<uint32_t>(z) * 0x9E3779B1u;
  h = (h ^ (h >> 16)) * 0x85EBCA77u;
  return h ^ (h >> 13);
}

double lattice(int32_t x, int32_t y, int32_t z, uint32_t seed) {
  return hash(x, y, z, seed) * (1.0 / 4294967296.0);
}

double smooth(double t) { return t * t * (3.0 - 2.0 * t); }

/// Value noise in [0, 1): trilinear blend of random lattice values with smoothstep weights.
double valueNoise(const Eigen::Vector3d& p, uint32_t seed) {
  const Eigen::Vector3d floor = p.array().floor();
  const int32_t x = static_cast<int32_t>(floor.x());
  const int32_t y = static_cast<int32_t>(floor.y());
  const int32_t z = static_cast<int32_t>(floor.z());
  const double u = smooth(p.x() - floor.x()), v = smooth(p.y() - floor.y());
  const double w = smooth(p.z() - floor.z());
  const auto lerp = [](double a, double b, double t) { return a + (b - a) * t; };
  const auto edge = [&](int dy, int dz) {
    return lerp(lattice(x, y + dy, z + dz, seed), lattice(x + 1, y + dy, z + dz, seed), u);
  };
  return lerp(lerp(edge(0, 0), edge(1, 0), v), lerp(edge(0, 1), edge(1, 1), v), w);
}

double fractalNoise(const Eigen::Vector3d& p, uint32_t seed, int octaves) {
  double sum = 0.0, amplitude = 0.5, total = 0.0;
  Eigen::Vector3d q = p;
  for (int octave = 0; octave < octaves; ++octave) {
    sum += amplitude * valueNoise(q, seed + octave);
    total += amplitude;
    amplitude *= 0.5;
    q = 2.03 * q + Eigen::Vector3d(17.1, 3.7, 9.2);
  }
  return sum / total;
}

/// How much of a detail of size `period_m` a pixel of footprint `footprint_m` keeps: all of it
/// down to two pixels, none at one pixel or less.
double keptShare(double period_m, double footprint_m) {
  if (footprint_m <= 0.0) return 1.0;
  return std::clamp(period_m / footprint_m - 1.0, 0.0, 1.0);
}

/// The share of [x - w/2, x + w/2] that the lines [k period - width/2, k period + width/2] cover
/// (a box filter over the footprint w); a point sample for a footprint well under the width.
double lineCoverage(double x, double w, double period, double width) {
  const double u = x + 0.5 * width;  // lines at [k period, k period + width] in u
  if (w < 0.05 * width) return u - period * std::floor(u / period) < width ? 1.0 : 0.0;
  const auto covered = [&](double t) {  // covered length of [0, t], negative for t < 0
    const double k = std::floor(t / period);
    return k * width + std::min(t - k * period, width);
  };
  return std::clamp((covered(u + 0.5 * w) - covered(u - 0.5 * w)) / w, 0.0, 1.0);
}

}  // namespace

cv::Vec3f solidTexture(const Eigen::Vector3d& X_W, unsigned seed) {
  constexpr double kBaseFrequency = 10.0;  // coarsest blobs about a tenth of the object's size
  const Eigen::Vector3d p = kBaseFrequency * X_W;
  const double hue = fractalNoise(0.4 * p, seed, 2);
  const double blobs = fractalNoise(p, seed + 101, 4);
  const double spots = valueNoise(3.0 * p, seed + 202);
  // Steep ramps through the middle of the noise range give sharp-edged blobs and spots.
  const auto ramp = [](double x, double gain) {
    return std::min(1.0, std::max(0.0, (x - 0.5) * gain + 0.5));
  };
  const double brightness = 0.12 + 0.55 * ramp(blobs, 8.0) + 0.33 * ramp(spots, 6.0);
  const double angle = 6.2831853 * hue;
  const cv::Vec3f tint(0.6f + 0.4f * std::cos(angle), 0.6f + 0.4f * std::cos(angle + 2.1),
                       0.6f + 0.4f * std::cos(angle + 4.2));
  return tint * static_cast<float>(brightness);
}

cv::Vec3f floorTexture(const Eigen::Vector2d& xy, double footprint_m, unsigned seed) {
  constexpr double kTile = 0.5, kJoint = 0.012;
  // Mottle: four octaves of value noise, blobs from 0.25 m down to 3 cm, each faded to its mean
  // once the pixel footprint nears its size.
  double sum = 0.0, total = 0.0, amplitude = 0.5, frequency = 4.0;
  for (int octave = 0; octave < 4; ++octave) {
    const Eigen::Vector3d p(frequency * xy.x(), frequency * xy.y(), 0.5 + 7.3 * octave);
    sum += amplitude *
           (0.5 + keptShare(1.0 / frequency, footprint_m) * (valueNoise(p, seed + octave) - 0.5));
    total += amplitude;
    amplitude *= 0.5;
    frequency *= 2.03;
  }
  const double mottle = sum / total;
  const double hue =
      0.5 + keptShare(1.0, footprint_m) *
                (valueNoise(Eigen::Vector3d(1.3 * xy.x(), 1.3 * xy.y(), 0.5), seed + 11) - 0.5);
  const auto tile_index = [&](double x) { return static_cast<int32_t>(std::floor(x / kTile)); };
  const double tile_shade = keptShare(kTile, 3.0 * footprint_m) *
                            (lattice(tile_index(xy.x()), tile_index(xy.y()), 0, seed + 57) - 0.5);
  const double brightness =
      std::clamp(0.75 + 1.1 * (mottle - 0.5), 0.45, 1.05) * (1.0 + 0.3 * tile_shade);
  const cv::Vec3f grey(0.60f, 0.61f, 0.62f), brown(0.38f, 0.53f, 0.70f);  // BGR
  const cv::Vec3f colour = grey + static_cast<float>(hue) * (brown - grey);
  const double joint_x = lineCoverage(xy.x(), footprint_m, kTile, kJoint);
  const double joint_y = lineCoverage(xy.y(), footprint_m, kTile, kJoint);
  const double joint = joint_x + joint_y - joint_x * joint_y;
  return colour * static_cast<float>(brightness * (1.0 - joint)) +
         cv::Vec3f(0.16f, 0.17f, 0.18f) * static_cast<float>(joint);
}

cv::Vec3f discTexture(const Eigen::Vector2d& offset_xy, double radius_m, unsigned seed) {
  const double r = offset_xy.norm() / radius_m;
  if (r > 0.95 && r < 0.97) return cv::Vec3f(0.85f, 0.85f, 0.82f);
  const double n = valueNoise(Eigen::Vector3d(6.0 * offset_xy.x(), 6.0 * offset_xy.y(), 0.5), seed);
  return cv::Vec3f(0.80f, 0.36f, 0.08f) * static_cast<float>(0.92 + 0.16 * n);
}

}  // namespace sift_hull
