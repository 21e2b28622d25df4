#include "filters/vote_verdict.h"

#include <Eigen/Core>
#include <algorithm>
#include <cmath>
#include <limits>
#include <string>

#include "sift_hull/filters/scaled_residuals.h"

namespace sift_hull {
namespace detail {
namespace {

/// The octave intervals of the keypoints of the matches `index` names (octaveInterval_px).
PairScales scalesOf(const PutativeMatches& input, const std::vector<size_t>& index) {
  PairScales scales;
  scales.left.reserve(index.size()), scales.right.reserve(index.size());
  for (size_t m : index) {
    scales.push(octaveInterval_px(input.left(m).size), octaveInterval_px(input.right(m).size));
  }
  return scales;
}

/// One motion's verdict on n matches: `smallest` takes the smaller residual, `verdict` gains
/// `place` (a homography) or `line` (a fundamental matrix whose frame the match agrees with) where
/// the judged residual is within t2. Unaliased arrays and selects only: the loop vectorises.
void judgeAgainst(size_t n, const float* __restrict residual, const float* __restrict judged,
                  const float* __restrict turn, const float* __restrict ratio,
                  const MotionFrame frame, float t2, uint8_t place, uint8_t line,
                  float* __restrict smallest, uint8_t* __restrict verdict) {
  for (size_t i = 0; i < n; ++i) {
    smallest[i] = std::min(smallest[i], residual[i]);
    const uint8_t agrees = frameAgrees(frame, turn[i], ratio[i]) ? line : uint8_t(0);
    const uint8_t within = judged[i] <= t2 ? uint8_t(0xff) : uint8_t(0);
    verdict[i] |= uint8_t(within & uint8_t(place | agrees));
  }
}

constexpr uint8_t kByPoint = 1, kByLine = 2;

}  // namespace

void keepUniqueImages(const PutativeMatches& input, const std::vector<size_t>& index,
                      uint8_t candidate, std::vector<uint8_t>* kept) {
  constexpr int kNone = -1;
  const size_t right_count = input.right_keypoints.size();
  std::vector<int> owner(right_count, kNone);  // per right keypoint: its kept match's position
  std::vector<size_t> outbid;  // the matches that found their right keypoint taken, or lost it
  const cv::DMatch* matches = input.matches.data();
  for (size_t k = 0; k < index.size(); ++k) {
    const cv::DMatch& match = matches[index[k]];
    const size_t r = static_cast<size_t>(match.trainIdx);  // a negative index becomes huge
    if ((*kept)[k] != candidate || r >= right_count) continue;
    const int o = owner[r];
    if (o == kNone) {
      owner[r] = static_cast<int>(k);
    } else if (match.distance < matches[index[size_t(o)]].distance) {
      outbid.push_back(size_t(o));
      owner[r] = static_cast<int>(k);
    } else {
      outbid.push_back(k);
    }
  }
  for (size_t k : outbid) {  // each at most once: a match is outbid when it claims or once owned
    const size_t r = static_cast<size_t>(matches[index[k]].trainIdx);
    const cv::KeyPoint &mine = input.left(index[k]), &theirs = input.left(index[size_t(owner[r])]);
    if (!(mine.size > 0.f) || !(theirs.size > 0.f)) continue;  // unknown sizes: left alone
    const cv::Point2f d = mine.pt - theirs.pt;
    const float reach = std::max(mine.size, theirs.size);
    if (d.x * d.x + d.y * d.y > reach * reach) (*kept)[k] = 0;
  }
}

void judgeMatches(const PutativeMatches& input, const PointPairs& all,
                  const std::vector<size_t>& index, const std::vector<TwoViewModel>& motions,
                  const std::vector<MotionFrame>& frames, const MatchFrames& match_frames,
                  const VoteRansacFilterConfig& config, FilterResult* result) {
  std::vector<float> best(all.size(), std::numeric_limits<float>::infinity()), r2, scaled;
  std::vector<uint8_t> explained(all.size(), 0);
  const std::string& unit = config.guided.tolerance_scale;
  const PairScales keypoints = unit == "keypoints" ? scalesOf(input, index) : PairScales();
  for (size_t k = 0; k < motions.size(); ++k) {
    const TwoViewModel& motion = motions[k];
    const float t2 = static_cast<float>(std::pow(motionThreshold(motion, config), 2));
    squaredResiduals(motion, all, &r2);
    // A fundamental matrix has no scale of its own: in the model's units its residuals are r2.
    const bool by_model = unit == "model" && motion.homography;
    if (unit == "keypoints") squaredScaledResiduals(motion, all, keypoints, &scaled);
    if (by_model) squaredScaledResiduals(motion, all, modelScales(motion, all), &scaled);
    const std::vector<float>& judged = unit == "keypoints" || by_model ? scaled : r2;
    // Bit 1: a homography places the point; bit 2: a fundamental matrix places it on a line,
    // and then only when its SIFT frame agrees with the motion's.
    const uint8_t place = motion.homography ? kByPoint : 0, line = motion.homography ? 0 : kByLine;
    judgeAgainst(r2.size(), r2.data(), judged.data(), match_frames.turn_deg.data(),
                 match_frames.scale_ratio.data(), frames[k], t2, place, line, best.data(),
                 explained.data());
  }
  // On a line, a right keypoint may be matched from several places along it; a homography's
  // tolerance already makes its matches of one right keypoint one place.
  keepUniqueImages(input, index, kByLine, &explained);
  // The smallest residual, px: square roots four or eight at a time (std::sqrt one by one, for
  // errno, was a tenth of the filter's time at 10,000 matches).
  Eigen::Map<Eigen::ArrayXf> smallest(best.data(), Eigen::Index(best.size()));
  smallest = smallest.sqrt();
  double* score = result->score.data();  // not reloaded through result on each write
  uint8_t* keep = result->keep.data();
  for (size_t i = 0; i < index.size(); ++i) {
    score[index[i]] = double(best[i]);
    keep[index[i]] = explained[i] != 0;
  }
}

}  // namespace detail
}  // namespace sift_hull
