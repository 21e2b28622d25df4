#include <Eigen/Dense>
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <limits>
#include <utility>

#include "sift_hull/filters/two_view_models.h"

namespace sift_hull {
namespace {

/// The pairs in Hartley-normalised coordinates (double), with the transforms that undo it.
struct Normalised {
  Eigen::MatrixX2d left, right;
  Eigen::Matrix3d T_left, T_right;
};

/// x' = s x + t for a list, in a plain loop (so that it vectorises).
void affineCopy(const std::vector<float>& x, double s, double t, double* out) {
  for (size_t i = 0; i < x.size(); ++i) out[i] = s * double(x[i]) + t;
}

Normalised normalise(const PointPairs& pairs) {
  Normalised n;
  n.T_left = hartleyNormalisation(pairs.left_x, pairs.left_y);
  n.T_right = hartleyNormalisation(pairs.right_x, pairs.right_y);
  n.left.resize(Eigen::Index(pairs.size()), 2), n.right.resize(Eigen::Index(pairs.size()), 2);
  // T = [s 0 tx; 0 s ty; 0 0 1] (hartleyNormalisation's form)
  affineCopy(pairs.left_x, n.T_left(0, 0), n.T_left(0, 2), n.left.col(0).data());
  affineCopy(pairs.left_y, n.T_left(1, 1), n.T_left(1, 2), n.left.col(1).data());
  affineCopy(pairs.right_x, n.T_right(0, 0), n.T_right(0, 2), n.right.col(0).data());
  affineCopy(pairs.right_y, n.T_right(1, 1), n.T_right(1, 2), n.right.col(1).data());
  return n;
}

/// A model found in normalised coordinates, in pixels.
TwoViewModel inPixels(const Eigen::Matrix3d& M, const Normalised& n, bool homography) {
  TwoViewModel model;
  model.homography = homography;
  model.matrix = homography ? Eigen::Matrix3d(n.T_right.inverse() * M * n.T_left)
                            : Eigen::Matrix3d(n.T_right.transpose() * M * n.T_left);
  const double norm = model.matrix.norm();
  if (norm > 0.0 && std::isfinite(norm)) model.matrix /= norm;
  return model;
}

/// A hypothesis' truncated quadratic score (lower is better) and inlier count among `counted`.
struct Score {
  double cost = std::numeric_limits<double>::infinity();
  size_t inliers_counted = 0;
};

/// Eight floats and eight counts: one vector register with AVX2, split by the compiler where
/// narrower.
typedef float FloatLanes __attribute__((vector_size(32)));
typedef int32_t IntLanes __attribute__((vector_size(32)));

/// Sums the truncated squares (each of 8 lanes its own rows, then the lanes in order, so that
/// the sum does not depend on the CPU's vector width) and counts the inliers among the pairs
/// `counted` marks.
__attribute__((target_clones("arch=x86-64-v4", "arch=x86-64-v3", "default"))) void truncatedScore(
    const float* r2, const uint8_t* counted, size_t n, float t2, double* cost, size_t* inliers) {
  FloatLanes partial = {};
  IntLanes count = {};
  const FloatLanes limit = partial + t2;
  const size_t whole = n / 8 * 8;
  for (size_t i = 0; i < whole; i += 8) {
    FloatLanes e;
    std::memcpy(&e, r2 + i, sizeof e);
    const IntLanes within = e <= limit;  // -1 where true
    partial += limit < e ? limit : e;    // std::min(e, t2): NaN stays NaN
    IntLanes mask;
    for (int k = 0; k < 8; ++k) mask[k] = counted[i + size_t(k)];
    count += within & mask;  // the mask is 0 or 1
  }
  double sum = 0.0;
  size_t total = 0;
  for (size_t i = whole; i < n; ++i) {
    sum += std::min(r2[i], t2), total += (r2[i] <= t2) & counted[i];
  }
  for (int k = 0; k < 8; ++k) sum += partial[k], total += size_t(count[k]);
  *cost = sum, *inliers = total;
}

/// A hypothesis' score, computed in blocks of kScoreBlock pairs that stop once its cost reaches
/// `bound` (the truncated squares only add up, so it could no longer score below it): a cost
/// of infinity then. `r2` holds every pair's squared residual when the cost is below `bound`.
constexpr size_t kScoreBlock = 128;

Score boundedScore(const TwoViewModel& model, const PointPairs& pairs, float t2,
                   const std::vector<uint8_t>& counted, double bound, std::vector<float>* r2) {
  r2->resize(pairs.size());
  Score score;
  score.cost = 0.0;
  for (size_t begin = 0; begin < pairs.size(); begin += kScoreBlock) {
    const size_t end = std::min(pairs.size(), begin + kScoreBlock);
    squaredResiduals(model, pairs, begin, end, r2->data());
    double cost = 0.0;
    size_t inliers = 0;
    truncatedScore(r2->data() + begin, counted.data() + begin, end - begin, t2, &cost, &inliers);
    score.cost += cost, score.inliers_counted += inliers;
    if (!(score.cost < bound)) return Score{};  // also NaN
  }
  return score;
}

std::vector<uint8_t> countedMask(const std::vector<int>& sample_from, size_t size) {
  std::vector<uint8_t> mask(size, sample_from.empty() ? 1 : 0);
  for (int i : sample_from) mask[size_t(i)] = 1;
  return mask;
}

/// m distinct entries of `from` (all indices when empty), drawn uniformly.
void drawSample(const std::vector<int>& from, size_t total, int m, std::mt19937* random,
                int* sample) {
  const size_t pool = from.empty() ? total : from.size();
  std::uniform_int_distribution<size_t> pick(0, pool - 1);
  for (int k = 0; k < m;) {
    const size_t p = pick(*random);
    const int index = from.empty() ? static_cast<int>(p) : from[p];
    if (std::find(sample, sample + k, index) == sample + k) sample[k++] = index;
  }
}

/// Local samples draw the rest of a sample among this many times m nearest others of its first
/// match, so that a sample spans more than the tightest cluster (whose model extrapolates badly).
constexpr size_t kLocalSpread = 4;

/// The first entry of `sample` (drawn already) and m - 1 others drawn among its kLocalSpread m
/// nearest in the left image, among `from` (all pairs when empty).
void nearbySample(const PointPairs& pairs, const std::vector<int>& from, int m,
                  std::mt19937* random, int* sample) {
  const size_t pool = from.empty() ? pairs.size() : from.size();
  const float x = pairs.left_x[size_t(sample[0])], y = pairs.left_y[size_t(sample[0])];
  std::vector<std::pair<float, int>> near;
  near.reserve(pool);
  for (size_t p = 0; p < pool; ++p) {
    const int i = from.empty() ? static_cast<int>(p) : from[p];
    if (i == sample[0]) continue;
    const float dx = pairs.left_x[size_t(i)] - x, dy = pairs.left_y[size_t(i)] - y;
    near.emplace_back(dx * dx + dy * dy, i);
  }
  const size_t reach = std::min(near.size(), kLocalSpread * size_t(m));
  std::partial_sort(near.begin(), near.begin() + reach, near.end());
  near.resize(reach);
  std::shuffle(near.begin(), near.end(), *random);
  for (int k = 1; k < m; ++k) sample[k] = near[size_t(k - 1)].second;
}

/// The minimal solver's models for the sample (normalised coordinates).
std::vector<Eigen::Matrix3d> solveMinimal(const Normalised& n, const int* sample, bool homography) {
  if (homography) {
    Eigen::Matrix<double, 4, 2> l, r;
    for (int k = 0; k < 4; ++k) l.row(k) = n.left.row(sample[k]), r.row(k) = n.right.row(sample[k]);
    Eigen::Matrix3d H;
    if (!fourPointHomography(l, r, &H)) return {};
    return {H};
  }
  Eigen::Matrix<double, 7, 2> l, r;
  for (int k = 0; k < 7; ++k) l.row(k) = n.left.row(sample[k]), r.row(k) = n.right.row(sample[k]);
  return sevenPointFundamental(l, r);
}

/// The local optimisation refits to at most this many inliers (evenly spread over them), so that
/// its cost does not grow with N; the polish of a finished model to at most kMaxPolishPoints.
constexpr size_t kMaxRefitPoints = 256;
constexpr size_t kMaxPolishPoints = 4096;

/// The weights of a refit, in place: w holds each pair's squared residual r2 and becomes Tukey's
/// biweight (1 - r2 / reach2)^2 (at least 1e-6), for F (`P`, the previous model, row-major)
/// times the Sampson weight 1 / (|(P l)_xy|^2 + |(P^T r)_xy|^2). Plain loops, so that they
/// vectorise.
__attribute__((target_clones("arch=x86-64-v4", "arch=x86-64-v3", "default"))) void refitWeights(
    const double* lx, const double* ly, const double* rx, const double* ry, size_t n, double reach2,
    const double* P, bool sampson, double* w) {
  for (size_t k = 0; k < n; ++k) {
    const double tukey = 1.0 - w[k] / reach2;
    w[k] = std::max(1e-6, tukey * tukey);
  }
  if (!sampson) return;
  for (size_t k = 0; k < n; ++k) {
    const double a0 = P[0] * lx[k] + P[1] * ly[k] + P[2];
    const double a1 = P[3] * lx[k] + P[4] * ly[k] + P[5];
    const double b0 = P[0] * rx[k] + P[3] * ry[k] + P[6];
    const double b1 = P[1] * rx[k] + P[4] * ry[k] + P[7];
    const double g = a0 * a0 + a1 * a1 + b0 * b0 + b1 * b1;
    w[k] *= g > 1e-12 ? 1.0 / g : 1e12;
  }
}

/// Weighted least squares over the inliers (at most max_points of them, evenly spread): Tukey's
/// biweight of each one's squared residual r2 under the previous model within `reach2`, for F
/// times the Sampson weight.
bool refit(const Normalised& n, std::vector<int> inliers, const std::vector<float>& r2,
           float reach2, const Eigen::Matrix3d& previous, bool homography, Eigen::Matrix3d* M,
           size_t max_points = kMaxRefitPoints) {
  if (inliers.size() > max_points) {
    std::vector<int> spread(max_points);
    for (size_t k = 0; k < max_points; ++k) spread[k] = inliers[k * inliers.size() / max_points];
    inliers.swap(spread);
  }
  const Eigen::Index count = Eigen::Index(inliers.size());
  Eigen::MatrixX2d l(count, 2), r(count, 2);
  Eigen::VectorXd w(count);
  const double *nlx = n.left.col(0).data(), *nly = n.left.col(1).data();
  const double *nrx = n.right.col(0).data(), *nry = n.right.col(1).data();
  double *lx = l.col(0).data(), *ly = l.col(1).data(), *rx = r.col(0).data(), *ry = r.col(1).data();
  for (Eigen::Index k = 0; k < count; ++k) {
    const size_t i = size_t(inliers[size_t(k)]);
    lx[k] = nlx[i], ly[k] = nly[i], rx[k] = nrx[i], ry[k] = nry[i];
    w(k) = double(r2[i]);
  }
  const Eigen::Matrix<double, 3, 3, Eigen::RowMajor> P = previous;
  refitWeights(lx, ly, rx, ry, size_t(count), double(reach2), P.data(), !homography, w.data());
  w /= w.maxCoeff();
  return homography ? leastSquaresHomography(l, r, w, M, &previous)
                    : leastSquaresFundamental(l, r, w, M, &previous);
}

std::vector<int> inliersOf(const std::vector<float>& r2, float t2) {
  std::vector<int> inliers(r2.size());
  size_t count = 0;
  for (size_t i = 0; i < r2.size(); ++i) {  // without a branch: write, then advance if within
    inliers[count] = static_cast<int>(i);
    count += r2[i] <= t2;
  }
  inliers.resize(count);
  return inliers;
}

/// The current best hypothesis, in normalised coordinates and in pixels, with its score.
struct Best {
  Eigen::Matrix3d normalised;
  TwoViewModel model;
  Score score;
};

/// The local optimisation refits to the matches within twice the inlier threshold (squared: 4),
/// Tukey-weighted by their residuals, so that a model fitted to part of a motion reaches the rest
/// of it and the threshold's edge does not bias it.
constexpr float kReach = 4.0f;
/// Reweighting stops when a refit improves the score by less than this share, or after
/// kMaxRefits refits.
constexpr double kConverged = 1e-3;
constexpr int kMaxRefits = 8;
/// A new best during the search gets this many refits: enough to set the count from its
/// refined support; the reweighting to convergence follows once, for the best of all.
constexpr int kRefitsPerNewBest = 1;

/// Iteratively reweighted least squares from the best model while the score improves; `r2`:
/// the best model's squared residuals.
void reweight(const PointPairs& pairs, const Normalised& n, const TwoViewFitSettings& s,
              const std::vector<uint8_t>& counted, float reach2, std::vector<float> r2, Best* best,
              size_t max_points = kMaxRefitPoints, int max_refits = kMaxRefits) {
  const float t2 = static_cast<float>(s.max_residual_px * s.max_residual_px);
  const size_t minimum = s.homography ? 4 : 8;
  std::vector<float> candidate_r2;
  for (int round = 0; round < max_refits; ++round) {
    const std::vector<int> inliers = inliersOf(r2, reach2);
    Eigen::Matrix3d M;
    if (inliers.size() < minimum ||
        !refit(n, inliers, r2, reach2, best->normalised, s.homography, &M, max_points)) {
      return;
    }
    const TwoViewModel candidate = inPixels(M, n, s.homography);
    const Score score =
        boundedScore(candidate, pairs, t2, counted, best->score.cost, &candidate_r2);
    if (!(score.cost < best->score.cost)) return;
    const bool converged = score.cost > (1.0 - kConverged) * best->score.cost;
    *best = Best{M, candidate, score};
    if (converged) return;
    r2.swap(candidate_r2);
  }
}

/// The inner RANSAC of LO-RANSAC: least squares over kInnerSamples random subsets of
/// kInnerSampleFactor m of the best model's inliers (within reach), which lets a model that is
/// its own least-squares fixed point (an epipole among the points explains some of them) give
/// way to the motion, and a homography fitted across two close motions (the Tukey weights
/// reach both) give way to one of them; the best of them, then the reweighting.
constexpr int kInnerSamples = 5;
constexpr size_t kInnerSampleFactor = 4;

void optimiseLocally(const PointPairs& pairs, const Normalised& n, const TwoViewFitSettings& s,
                     const std::vector<uint8_t>& counted, std::mt19937* random, Best* best) {
  const float t2 = static_cast<float>(s.max_residual_px * s.max_residual_px), reach2 = kReach * t2;
  const size_t size = kInnerSampleFactor * (s.homography ? 4 : 7);
  std::vector<float> r2, candidate_r2, best_r2;
  squaredResiduals(best->model, pairs, &r2);
  std::vector<int> inliers = inliersOf(r2, reach2);
  const Best start = *best;
  best_r2 = r2;  // r2 stays: the inner refits weight by the start model's residuals
  for (int k = 0; k < kInnerSamples && inliers.size() > size; ++k) {
    std::shuffle(inliers.begin(), inliers.end(), *random);
    const std::vector<int> subset(inliers.begin(), inliers.begin() + size);
    Eigen::Matrix3d M;
    if (!refit(n, subset, r2, reach2, start.normalised, s.homography, &M)) continue;
    const TwoViewModel candidate = inPixels(M, n, s.homography);
    const Score score =
        boundedScore(candidate, pairs, t2, counted, best->score.cost, &candidate_r2);
    if (score.cost < best->score.cost) {
      *best = Best{M, candidate, score};
      best_r2.swap(candidate_r2);
    }
  }
  reweight(pairs, n, s, counted, reach2, std::move(best_r2), best);
}

/// What one fit searches over.
struct Search {
  const PointPairs& pairs;
  Normalised n;
  const TwoViewFitSettings& settings;
  std::vector<uint8_t> counted;
  const std::vector<int>& sample_from;
};

/// The hypothesis loop: minimal samples until the count that the best support asks for (or
/// max_iterations); each new best reweighted at once. Returns the iterations run.
int searchHypotheses(const Search& s, std::mt19937* random, Best* best) {
  const TwoViewFitSettings& settings = s.settings;
  const int m = settings.homography ? 4 : 7;
  const size_t pool = s.sample_from.empty() ? s.pairs.size() : s.sample_from.size();
  const float t2 = static_cast<float>(settings.max_residual_px * settings.max_residual_px);
  std::vector<float> r2;
  int sample[7];
  int iterations = 0, needed = settings.max_iterations;
  for (; iterations < needed; ++iterations) {
    drawSample(s.sample_from, s.pairs.size(), settings.local_samples ? 1 : m, random, sample);
    if (settings.local_samples) nearbySample(s.pairs, s.sample_from, m, random, sample);
    for (const Eigen::Matrix3d& M : solveMinimal(s.n, sample, settings.homography)) {
      const TwoViewModel candidate = inPixels(M, s.n, settings.homography);
      const Score score = boundedScore(candidate, s.pairs, t2, s.counted, best->score.cost, &r2);
      if (!(score.cost < best->score.cost)) continue;
      *best = Best{M, candidate, score};
      // LO-RANSAC: every new best is reweighted at once, and the refined support sets the
      // count; the inner samples follow once, for the best of all.
      if (best->score.inliers_counted >= settings.min_inliers_to_refine) {
        reweight(s.pairs, s.n, settings, s.counted, kReach * t2, std::move(r2), best,
                 kMaxRefitPoints, kRefitsPerNewBest);  // r2 is rewritten by the next score
      }
      needed = std::max(iterations + 1,
                        ransacIterations(double(best->score.inliers_counted) / double(pool), m,
                                         settings.confidence, settings.max_iterations));
    }
  }
  return iterations;
}

/// A model in pixels, in the normalised coordinates of `n` (the inverse of inPixels, unit norm).
Eigen::Matrix3d inNormalised(const TwoViewModel& model, const Normalised& n) {
  Eigen::Matrix3d M =
      model.homography
          ? Eigen::Matrix3d(n.T_right * model.matrix * n.T_left.inverse())
          : Eigen::Matrix3d(n.T_right.inverse().transpose() * model.matrix * n.T_left.inverse());
  const double norm = M.norm();
  if (norm > 0.0 && std::isfinite(norm)) M /= norm;
  return M;
}

}  // namespace

TwoViewModel polishTwoViewModel(const PointPairs& pairs, const TwoViewModel& model,
                                double max_residual_px) {
  if (pairs.size() < (model.homography ? 4u : 8u)) return model;
  TwoViewFitSettings settings;
  settings.homography = model.homography;
  settings.max_residual_px = max_residual_px;
  const Normalised n = normalise(pairs);
  const std::vector<uint8_t> counted(pairs.size(), 1);
  const float t2 = static_cast<float>(max_residual_px * max_residual_px);
  std::vector<float> r2;
  // Scored as the candidates are (in blocks), so that equal models compare equal.
  Best best{inNormalised(model, n), model,
            boundedScore(model, pairs, t2, counted, std::numeric_limits<double>::infinity(), &r2)};
  if (!best.normalised.allFinite() || !std::isfinite(best.score.cost)) return model;
  reweight(pairs, n, settings, counted, kReach * t2, std::move(r2), &best, kMaxPolishPoints);
  return best.model;
}

TwoViewFit fitTwoViewModel(const PointPairs& pairs, const std::vector<int>& sample_from,
                           const TwoViewFitSettings& settings, std::mt19937* random) {
  TwoViewFit fit;
  const int m = settings.homography ? 4 : 7;
  const size_t pool = sample_from.empty() ? pairs.size() : sample_from.size();
  if (pool < size_t(m) || pairs.size() < size_t(m) + 1) return fit;
  const Search search{pairs, normalise(pairs), settings, countedMask(sample_from, pairs.size()),
                      sample_from};
  Best best;
  fit.iterations = searchHypotheses(search, random, &best);
  if (!std::isfinite(best.score.cost)) return fit;
  if (best.score.inliers_counted >= settings.min_inliers_to_refine) {
    optimiseLocally(pairs, search.n, settings, search.counted, random, &best);
  }
  const float t2 = static_cast<float>(settings.max_residual_px * settings.max_residual_px);
  std::vector<float> r2;
  squaredResiduals(best.model, pairs, &r2);
  fit.found = true;
  fit.model = best.model;
  fit.inliers = inliersOf(r2, t2);
  fit.cost = best.score.cost;
  return fit;
}

}  // namespace sift_hull
