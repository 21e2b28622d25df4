#include "synthetic/texture.h"

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

}  // namespace sift_hull
