#include "sift_hull/filters/vote_ransac.h"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <numeric>
#include <random>
#include <stdexcept>
#include <vector>

#include "filters/densest_window.h"
#include "filters/motion_frame.h"
#include "filters/vote_verdict.h"
#include "sift_hull/filters/two_view_models.h"

namespace sift_hull {
namespace {

/// A further motion must explain this share of its voted pool: the clear majority of the cluster
/// its matches voted for (mismatches of a repeated texture can agree with an F on half of one).
constexpr double kFurtherMotionShare = 2.0 / 3.0;
/// A local sample is clean about as often as a global sample of two matches: its seed must lie on
/// the motion and its neighbourhood must not straddle another.
constexpr int kLocalSampleWeight = 2;
/// A motion is compared with chance within a residual where chance explains at most this share of
/// the pairs: 4 times as many then asks it to explain a quarter of them (at the default thresholds
/// chance explains far less, and the comparison is made at the threshold itself).
constexpr double kChanceShareJudged = 1.0 / 16.0;

/// The matches the motions are fitted to, with what each one votes for (NaN: no vote).
struct FitSet {
  PointPairs pairs;
  std::vector<float> rotation_deg;  ///< angle_right - angle_left in [0, 360)
  std::vector<float> log2_scale;    ///< log2(size_right / size_left)
};

float rotationOf(const cv::KeyPoint& l, const cv::KeyPoint& r) {
  if (!std::isfinite(l.angle) || !std::isfinite(r.angle) || l.angle < 0.f || r.angle < 0.f) {
    return NAN;  // OpenCV's -1: no orientation
  }
  double d = double(r.angle) - double(l.angle);  // in (-360, 360) for angles in [0, 360)
  if (d < 0.0) d += 360.0;
  if (!(d < 360.0)) {  // angles beyond a turn (or d + 360 rounded up to it): the remainder
    d = std::fmod(double(r.angle) - double(l.angle), 360.0);
    if (d < 0.0) d += 360.0;
  }
  return static_cast<float>(d);
}

float log2ScaleOf(const cv::KeyPoint& l, const cv::KeyPoint& r) {
  if (!(l.size > 0.f) || !(r.size > 0.f)) return NAN;
  const double s = std::log2(double(r.size) / double(l.size));
  return std::isfinite(s) ? static_cast<float>(s) : NAN;
}

/// `finite`: the matches with finite positions, in order.
FitSet fitSetOf(const PutativeMatches& input, const std::vector<size_t>& finite, size_t max_points,
                unsigned seed) {
  std::vector<size_t> chosen;
  if (finite.size() <= max_points) {
    chosen = finite;
  } else {  // a uniform sample, kept in the matches' order
    std::mt19937 random(seed);
    std::vector<size_t> order(finite.size());
    std::iota(order.begin(), order.end(), size_t(0));
    std::vector<uint8_t> taken(finite.size(), 0);
    for (size_t k = 0; k < max_points; ++k) {  // the first max_points steps of a shuffle
      std::uniform_int_distribution<size_t> pick(k, order.size() - 1);
      std::swap(order[k], order[pick(random)]);
      taken[order[k]] = 1;
    }
    chosen.reserve(max_points);
    for (size_t p = 0; p < finite.size(); ++p) {
      if (taken[p]) chosen.push_back(finite[p]);
    }
  }
  FitSet set;
  const size_t n = chosen.size();
  set.pairs.left_x.resize(n), set.pairs.left_y.resize(n);
  set.pairs.right_x.resize(n), set.pairs.right_y.resize(n);
  set.rotation_deg.resize(n), set.log2_scale.resize(n);
  for (size_t k = 0; k < n; ++k) {
    const cv::KeyPoint &l = input.left(chosen[k]), &r = input.right(chosen[k]);
    set.pairs.left_x[k] = l.pt.x, set.pairs.left_y[k] = l.pt.y;
    set.pairs.right_x[k] = r.pt.x, set.pairs.right_y[k] = r.pt.y;
    set.rotation_deg[k] = rotationOf(l, r);
    set.log2_scale[k] = log2ScaleOf(l, r);
  }
  return set;
}

FitSet subsetOf(const FitSet& set, const std::vector<int>& members) {
  FitSet sub;
  sub.pairs.reserve(members.size());
  sub.rotation_deg.reserve(members.size()), sub.log2_scale.reserve(members.size());
  for (int i : members) {
    sub.pairs.push(set.pairs.left_x[i], set.pairs.left_y[i], set.pairs.right_x[i],
                   set.pairs.right_y[i]);
    sub.rotation_deg.push_back(set.rotation_deg[i]);
    sub.log2_scale.push_back(set.log2_scale[i]);
  }
  return sub;
}

/// The matches the vote chooses to sample from; empty when the rotations do not cluster enough
/// (`require_cluster`: at least twice what evenly spread rotations would put in the window).
/// `frame`: the medians of the two windows, the turn and scale change the pool shares.
std::vector<int> votedPool(const FitSet& set, const VoteRansacConfig& config, bool require_cluster,
                           detail::MotionFrame* frame) {
  std::vector<int> voting;
  for (size_t i = 0; i < set.pairs.size(); ++i) {
    if (std::isfinite(set.rotation_deg[i]) && std::isfinite(set.log2_scale[i])) {
      voting.push_back(static_cast<int>(i));
    }
  }
  if (voting.empty()) return {};
  size_t count = 0;
  const double half = config.max_angle_deg;
  float turn = NAN, log2_scale = NAN;
  const std::vector<int> turned =
      detail::densestWindow(set.rotation_deg, voting, half, 360.0, &count, &turn);
  const double even = double(voting.size()) * std::min(1.0, 2.0 * half / 360.0);
  if (require_cluster && double(count) < 2.0 * even) return {};
  std::vector<int> pool = detail::densestWindow(
      set.log2_scale, turned, std::log2(config.max_scale_ratio), 0.0, &count, &log2_scale);
  *frame = detail::motionFrame(turn, log2_scale);
  return pool;
}

/// A model's squared residuals of the pairs when each left point meets the right point of another
/// match (the right points shifted by half the set): what chance alone gives it.
void chanceResiduals(const TwoViewModel& model, const PointPairs& pairs, std::vector<float>* r2) {
  PointPairs shuffled = pairs;
  const size_t n = pairs.size(), shift = n == 0 ? 0 : (n / 2 + 1) % n;
  // right point i of the shuffled pairs is right point (i + shift) mod n
  std::rotate_copy(pairs.right_x.begin(), pairs.right_x.begin() + long(shift), pairs.right_x.end(),
                   shuffled.right_x.begin());
  std::rotate_copy(pairs.right_y.begin(), pairs.right_y.begin() + long(shift), pairs.right_y.end(),
                   shuffled.right_y.begin());
  squaredResiduals(model, shuffled, r2);
}

size_t countWithin(const std::vector<float>& r2, float t2) {
  return static_cast<size_t>(std::count_if(r2.begin(), r2.end(), [&](float e) { return e <= t2; }));
}

size_t countBelow(const std::vector<float>& r2, float t2) {
  return static_cast<size_t>(std::count_if(r2.begin(), r2.end(), [&](float e) { return e < t2; }));
}

/// How many pairs a model must explain within `threshold_px` to be more than chance: 4 times what
/// chance gives it. Where chance alone explains more than kChanceShareJudged of the pairs within
/// the threshold (a wide threshold over points that spread little: no motion with mismatches
/// could then explain 4 times as many), the model is compared with chance within the narrower
/// residual where chance explains that share, since a motion's matches lie near it at any
/// threshold and chance's do not: 0 when it explains 4 times as many there, else more than all.
size_t neededBeyondChance(const TwoViewModel& model, const PointPairs& pairs, double threshold_px) {
  std::vector<float> chance_r2, r2;
  chanceResiduals(model, pairs, &chance_r2);
  const size_t chance = countWithin(chance_r2, static_cast<float>(threshold_px * threshold_px));
  const size_t share = static_cast<size_t>(kChanceShareJudged * double(pairs.size()));
  if (chance <= share || share == 0) return 4 * chance;
  std::nth_element(chance_r2.begin(), chance_r2.begin() + long(share), chance_r2.end());
  const float narrower2 = chance_r2[share];  // at most `share` chance residuals lie below it
  squaredResiduals(model, pairs, &r2);
  const size_t beyond = 4 * std::max<size_t>(1, countBelow(chance_r2, narrower2));
  return countBelow(r2, narrower2) >= beyond ? 0 : pairs.size() + 1;
}

size_t countIn(const std::vector<int>& inliers, const std::vector<int>& pool, size_t size) {
  std::vector<uint8_t> in(size, 0);
  for (int i : inliers) in[size_t(i)] = 1;
  size_t count = 0;
  for (int i : pool) count += in[size_t(i)];
  return count;
}

/// The homography of the set, searched for in two stages when F was found: first only as long
/// as H needs to match guided_homography_share of F's inliers, then, when what it found comes
/// within half of that, as long as its own inlier share says (a plane's F explains mismatches
/// along its epipolar lines too, so H may win from fewer inliers than F has).
TwoViewFit fitHomography(const FitSet& set, const std::vector<int>& pool, const TwoViewFit& F,
                         TwoViewFitSettings settings, const VoteRansacFilterConfig& config,
                         std::mt19937* random) {
  const double share = config.guided.homography_share;
  const int cap = settings.max_iterations;
  settings.homography = true;
  settings.max_residual_px = config.guided.max_transfer_px;
  if (!F.found) return fitTwoViewModel(set.pairs, pool, settings, random);
  const size_t pool_size = pool.empty() ? set.pairs.size() : pool.size();
  const double w = double(countIn(F.inliers, pool, set.pairs.size())) / double(pool_size);
  settings.max_iterations = std::min(cap, ransacIterations(share * w, 4, settings.confidence, cap));
  settings.min_inliers_to_refine = size_t(0.25 * share * w * double(pool_size));
  const TwoViewFit first = fitTwoViewModel(set.pairs, pool, settings, random);
  const bool close = first.found && first.inliers.size() >= 0.5 * share * F.inliers.size();
  if (!close || first.iterations < settings.max_iterations || settings.max_iterations >= cap) {
    return first;  // stopped by its own count, or already searched as long as allowed
  }
  settings.max_iterations = cap, settings.min_inliers_to_refine = 0;
  const TwoViewFit second = fitTwoViewModel(set.pairs, pool, settings, random);
  return second.found && second.cost < first.cost ? second : first;
}

/// The better of F and H for the set, sampled from the pool; not found when neither qualifies.
/// A further motion (`further`) is sampled locally, searched for at most as long as a motion that
/// explains kFurtherMotionShare of its pool needs, and must explain that share.
TwoViewFit fitMotion(const FitSet& set, const std::vector<int>& pool, bool further,
                     const VoteRansacFilterConfig& config, std::mt19937* random) {
  const RobustFitConfig& fit = config.magsac;
  const GuidedConfig& guided = config.guided;
  const int cap = further ? ransacIterations(kFurtherMotionShare, kLocalSampleWeight,
                                             fit.confidence, fit.max_iterations)
                          : fit.max_iterations;
  TwoViewFitSettings settings{false, fit.max_epipolar_px, fit.confidence, cap, further};
  const TwoViewFit F = fitTwoViewModel(set.pairs, pool, settings, random);
  const size_t pool_size = pool.empty() ? set.pairs.size() : pool.size();
  const TwoViewFit H = fitHomography(set, pool, F, settings, config, random);
  const bool use_h =
      H.found && (!F.found || H.inliers.size() >= guided.homography_share * F.inliers.size());
  TwoViewFit chosen = use_h ? H : F;
  const double threshold = use_h ? guided.max_transfer_px : fit.max_epipolar_px;
  size_t needed = std::max<size_t>(size_t(guided.min_model_inliers),
                                   neededBeyondChance(chosen.model, set.pairs, threshold));
  if (further)
    needed = std::max<size_t>(needed, size_t(std::ceil(kFurtherMotionShare * pool_size)));
  const size_t explained_in_pool =
      further ? countIn(chosen.inliers, pool, set.pairs.size()) : chosen.inliers.size();
  if (!chosen.found || chosen.inliers.size() < needed || explained_in_pool < needed) {
    chosen.found = false;
  }
  return chosen;
}

std::vector<int> unexplained(const FitSet& set, const std::vector<int>& inliers) {
  std::vector<uint8_t> in(set.pairs.size(), 0);
  for (int i : inliers) in[size_t(i)] = 1;
  std::vector<int> rest;
  for (size_t i = 0; i < in.size(); ++i) {
    if (!in[i]) rest.push_back(static_cast<int>(i));
  }
  return rest;
}

/// Whether most inliers of a further motion lie within twice the threshold of an earlier motion:
/// then they are what the earlier one left at its threshold's edge, not a motion of their own.
bool leftoverOf(const std::vector<TwoViewModel>& earlier, const FitSet& set,
                const std::vector<int>& inliers, const VoteRansacFilterConfig& config) {
  if (earlier.empty()) return false;
  const FitSet found = subsetOf(set, inliers);
  std::vector<uint8_t> near(found.pairs.size(), 0);
  std::vector<float> r2;
  for (const TwoViewModel& motion : earlier) {
    squaredResiduals(motion, found.pairs, &r2);
    const float t2 = static_cast<float>(4.0 * std::pow(detail::motionThreshold(motion, config), 2));
    for (size_t i = 0; i < r2.size(); ++i) near[i] |= r2[i] <= t2;
  }
  return 2 * size_t(std::count(near.begin(), near.end(), 1)) >= near.size();
}

/// Up to guided_max_models motions, each fitted to what the earlier ones leave unexplained, with
/// the SIFT frame the vote found for each (`frames`, in the same order; unknown where it sampled
/// from all).
std::vector<TwoViewModel> fitMotions(FitSet set, const VoteRansacFilterConfig& config,
                                     std::vector<detail::MotionFrame>* frames) {
  std::mt19937 random(static_cast<unsigned>(config.magsac.seed));
  std::vector<TwoViewModel> motions;
  while (static_cast<int>(motions.size()) < config.guided.max_models &&
         set.pairs.size() >= static_cast<size_t>(config.guided.min_model_inliers)) {
    const bool further = !motions.empty();
    detail::MotionFrame frame;  // unknown unless the vote chooses the pool
    std::vector<int> pool = votedPool(set, config.vote_ransac, further, &frame);
    const size_t least = 2 * static_cast<size_t>(config.guided.min_model_inliers);
    if (further && pool.size() < least) break;  // no cluster that could hold a further motion
    if (pool.size() < 16) {                     // too few votes to sample from: sample from all
      pool.clear();
      frame = detail::MotionFrame();
    }
    const TwoViewFit motion = fitMotion(set, pool, further, config, &random);
    if (!motion.found || leftoverOf(motions, set, motion.inliers, config)) break;
    motions.push_back(motion.model);
    frames->push_back(frame);
    set = subsetOf(set, unexplained(set, motion.inliers));
  }
  return motions;
}

/// The matches with finite positions, as pairs, with their indices into input.matches.
PointPairs finitePairs(const PutativeMatches& input, std::vector<size_t>* index,
                       detail::MatchFrames* frames = nullptr) {
  // Written in place rather than pushed: this gather is a quarter of the filter's time at 10,000
  // matches.
  const size_t n = input.matches.size();
  PointPairs all;
  all.left_x.resize(n), all.left_y.resize(n), all.right_x.resize(n), all.right_y.resize(n);
  index->resize(n);
  if (frames) frames->resize(n);
  size_t k = 0;
  for (size_t m = 0; m < n; ++m) {
    const cv::KeyPoint &l = input.left(m), &r = input.right(m);
    if (!(std::isfinite(l.pt.x) && std::isfinite(l.pt.y) && std::isfinite(r.pt.x) &&
          std::isfinite(r.pt.y))) {
      continue;  // as input.hasFinitePositions(m)
    }
    all.left_x[k] = l.pt.x, all.left_y[k] = l.pt.y, all.right_x[k] = r.pt.x,
    all.right_y[k] = r.pt.y;
    (*index)[k] = m;
    if (frames) frames->set(k, l.angle, l.size, r.angle, r.size);
    ++k;
  }
  all.left_x.resize(k), all.left_y.resize(k), all.right_x.resize(k), all.right_y.resize(k);
  index->resize(k);
  if (frames) frames->resize(k);
  return all;
}

}  // namespace

namespace {

/// The refinement of a motion against all the matches sees those within this many times its
/// threshold (the rest cannot join it in a few reweighting steps), at most kMaxPolishPoints of
/// them, evenly spread, so that its cost is one residual per match beyond that (512 near
/// matches hold more of the motion than the fit set's sample of 500 putatives does).
constexpr double kPolishReach = 3.0;
constexpr size_t kMaxPolishPoints = 512;

/// The motion refined against the matches within kPolishReach times its threshold that `taken`
/// does not mark (those an earlier motion explains, so that a further motion is not drawn onto
/// an earlier one's matches).
TwoViewModel polished(const PointPairs& all, const std::vector<uint8_t>& taken,
                      const TwoViewModel& motion, double threshold_px) {
  std::vector<float> r2;
  squaredResiduals(motion, all, &r2);
  const float reach2 = static_cast<float>(std::pow(kPolishReach * threshold_px, 2));
  std::vector<int> near;
  for (size_t i = 0; i < r2.size(); ++i) {
    if (r2[i] <= reach2 && !taken[i]) near.push_back(static_cast<int>(i));
  }
  const size_t count = std::min(near.size(), kMaxPolishPoints);
  PointPairs chosen;
  chosen.reserve(count);
  for (size_t k = 0; k < count; ++k) {
    const size_t i = size_t(near[k * near.size() / count]);
    chosen.push(all.left_x[i], all.left_y[i], all.right_x[i], all.right_y[i]);
  }
  return polishTwoViewModel(chosen, motion, threshold_px);
}

/// The motions of the matches `all` (the finite ones of `input`): fitted to at most
/// vote_ransac_max_fit_points of them, then, when that was a sample, each refined against the
/// matches near it that the motions before it do not explain.
std::vector<TwoViewModel> motionsOf(const PutativeMatches& input, const PointPairs& all,
                                    const std::vector<size_t>& index,
                                    const VoteRansacFilterConfig& config,
                                    std::vector<detail::MotionFrame>* frames) {
  validate(config.vote_ransac);
  validate(config.guided);
  validate(config.magsac, "magsac");
  const size_t max_points = size_t(config.vote_ransac.max_fit_points);
  std::vector<TwoViewModel> motions =
      fitMotions(fitSetOf(input, index, max_points, static_cast<unsigned>(config.magsac.seed)),
                 config, frames);
  if (all.size() > max_points) {
    std::vector<uint8_t> taken(all.size(), 0);
    std::vector<float> r2;
    for (size_t k = 0; k < motions.size(); ++k) {
      const double threshold = detail::motionThreshold(motions[k], config);
      motions[k] = polished(all, taken, motions[k], threshold);
      if (k + 1 == motions.size()) break;
      squaredResiduals(motions[k], all, &r2);
      const float t2 = static_cast<float>(threshold * threshold);
      for (size_t i = 0; i < r2.size(); ++i) taken[i] |= r2[i] <= t2;
    }
  }
  return motions;
}

}  // namespace

std::vector<TwoViewModel> voteRansacMotions(const PutativeMatches& input,
                                            const VoteRansacFilterConfig& config) {
  std::vector<size_t> index;
  const PointPairs all = finitePairs(input, &index);
  std::vector<detail::MotionFrame> frames;
  return motionsOf(input, all, index, config, &frames);
}

FilterResult filterVoteRansac(const PutativeMatches& input, const VoteRansacFilterConfig& config) {
  FilterResult result = FilterResult::keepingNone(input.matches.size());
  std::vector<size_t> index;
  detail::MatchFrames match_frames;
  const PointPairs all = finitePairs(input, &index, &match_frames);
  std::vector<detail::MotionFrame> frames;
  const std::vector<TwoViewModel> motions = motionsOf(input, all, index, config, &frames);
  if (!motions.empty())
    detail::judgeMatches(input, all, index, motions, frames, match_frames, config, &result);
  return result;
}

}  // namespace sift_hull
