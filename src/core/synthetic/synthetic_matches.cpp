#include "sift_hull/synthetic/synthetic_matches.h"

#include <Eigen/Geometry>
#include <cmath>
#include <random>
#include <stdexcept>

namespace sift_hull {
namespace {

using Random = std::mt19937;

/// The similarity transform of SyntheticMatchConfig, in image coordinates (x right, y down): a
/// positive rotation turns x towards y, as keypoint angles do.
struct Similarity {
  Eigen::Matrix2d scaled_rotation;
  Eigen::Vector2d centre, shift;
  Eigen::Vector2d operator()(const Eigen::Vector2d& x) const {
    return scaled_rotation * (x - centre) + centre + shift;
  }
};

Similarity similarityOf(const SyntheticMatchConfig& config) {
  const double rotation = config.rotation_deg * M_PI / 180.0;
  return {config.scale * Eigen::Rotation2Dd(rotation).toRotationMatrix(),
          Eigen::Vector2d(config.image_size.width, config.image_size.height) / 2.0,
          Eigen::Vector2d(config.shift_px, config.shift_px)};
}

bool inside(const Eigen::Vector2d& x, cv::Size size) {
  return x.x() >= 0.0 && x.y() >= 0.0 && x.x() < size.width && x.y() < size.height;
}

Eigen::Vector2d uniformPosition(cv::Size size, Random* random) {
  std::uniform_real_distribution<double> u(0.0, size.width), v(0.0, size.height);
  return {u(*random), v(*random)};
}

cv::KeyPoint keypointAt(const Eigen::Vector2d& x, double angle_deg, double size_px) {
  const double wrapped = std::fmod(std::fmod(angle_deg, 360.0) + 360.0, 360.0);
  return cv::KeyPoint(static_cast<float>(x.x()), static_cast<float>(x.y()),
                      static_cast<float>(size_px), static_cast<float>(wrapped));
}

void append(LabelledMatches* matches, const cv::KeyPoint& left, const cv::KeyPoint& right,
            MatchTruth truth) {
  PutativeMatches& putative = matches->putative;
  putative.matches.emplace_back(static_cast<int>(putative.left_keypoints.size()),
                                static_cast<int>(putative.right_keypoints.size()), 0.f);
  putative.left_keypoints.push_back(left);
  putative.right_keypoints.push_back(right);
  matches->truth.push_back(truth);
}

void appendInlier(const SyntheticMatchConfig& config, const Similarity& transform,
                  LabelledMatches* matches, Random* random) {
  std::normal_distribution<double> position_noise(0.0, config.position_noise_px);
  std::normal_distribution<double> angle_noise(0.0, config.angle_noise_deg);
  std::uniform_real_distribution<double> angle(0.0, 360.0), size(2.0, 12.0);
  for (;;) {
    const Eigen::Vector2d left = uniformPosition(config.image_size, random);
    const Eigen::Vector2d noise(position_noise(*random), position_noise(*random));
    const Eigen::Vector2d right = transform(left) + noise;
    if (!inside(right, config.image_size)) continue;
    const double left_angle = angle(*random), left_size = size(*random);
    append(matches, keypointAt(left, left_angle, left_size),
           keypointAt(right, left_angle + config.rotation_deg + angle_noise(*random),
                      left_size * config.scale),
           MatchTruth::kCorrect);
    return;
  }
}

size_t outliersFor(size_t inliers, double fraction) {
  if (!(fraction >= 0.0 && fraction < 1.0)) {
    throw std::invalid_argument("outlier fraction must be in [0, 1)");
  }
  return static_cast<size_t>(std::lround(inliers * fraction / (1.0 - fraction)));
}

}  // namespace

LabelledMatches syntheticMatches(const SyntheticMatchConfig& config) {
  if (config.image_size.width <= 0 || config.image_size.height <= 0 || !(config.scale > 0.0)) {
    throw std::invalid_argument("SyntheticMatchConfig: image size and scale must be positive");
  }
  LabelledMatches matches;
  matches.putative.left_image_size = matches.putative.right_image_size = config.image_size;
  Random random(config.seed);
  const Similarity transform = similarityOf(config);
  for (size_t i = 0; i < config.inliers; ++i) appendInlier(config, transform, &matches, &random);
  injectMismatches(&matches, config.outlier_fraction, config.seed + 1);
  return matches;
}

void injectMismatches(LabelledMatches* matches, double fraction, unsigned seed) {
  PutativeMatches& putative = matches->putative;
  const size_t count = outliersFor(putative.matches.size(), fraction);
  Random random(seed);
  std::uniform_real_distribution<double> angle(0.0, 360.0);
  std::uniform_int_distribution<size_t> pick(
      0, std::max<size_t>(1, putative.left_keypoints.size()) - 1);
  for (size_t k = 0; k < count; ++k) {
    const double size_px =
        putative.left_keypoints.empty() ? 4.0 : putative.left_keypoints[pick(random)].size;
    const Eigen::Vector2d left = uniformPosition(putative.left_image_size, &random);
    const Eigen::Vector2d right = uniformPosition(putative.right_image_size, &random);
    append(matches, keypointAt(left, angle(random), size_px),
           keypointAt(right, angle(random), size_px), MatchTruth::kWrong);
  }
}

LabelledMatches tileMatches(const LabelledMatches& matches, int copies_x, int copies_y) {
  if (copies_x < 1 || copies_y < 1) throw std::invalid_argument("tileMatches: copies must be >= 1");
  const PutativeMatches& in = matches.putative;
  LabelledMatches tiled;
  PutativeMatches& out = tiled.putative;
  out.left_image_size =
      cv::Size(in.left_image_size.width * copies_x, in.left_image_size.height * copies_y);
  out.right_image_size =
      cv::Size(in.right_image_size.width * copies_x, in.right_image_size.height * copies_y);
  out.F_right_left = in.F_right_left;
  for (int cy = 0; cy < copies_y; ++cy) {
    for (int cx = 0; cx < copies_x; ++cx) {
      const cv::Point2f shift(static_cast<float>(cx * in.left_image_size.width),
                              static_cast<float>(cy * in.left_image_size.height));
      for (size_t m = 0; m < in.matches.size(); ++m) {
        cv::KeyPoint left = in.left(m), right = in.right(m);
        left.pt += shift;
        right.pt += shift;
        append(&tiled, left, right,
               matches.truth.empty() ? MatchTruth::kUnknown : matches.truth[m]);
        out.matches.back().distance = in.matches[m].distance;
      }
    }
  }
  return tiled;
}

}  // namespace sift_hull
