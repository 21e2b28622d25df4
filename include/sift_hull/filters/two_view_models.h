#pragma once

#include <Eigen/Core>
#include <cstddef>
#include <random>
#include <vector>

namespace sift_hull {

/// Matched points as four float arrays (pixels), so that scoring a model over them vectorises.
struct PointPairs {
  std::vector<float> left_x, left_y, right_x, right_y;
  size_t size() const { return left_x.size(); }
  void push(float lx, float ly, float rx, float ry) {  // inline: called once per match
    left_x.push_back(lx), left_y.push_back(ly), right_x.push_back(rx), right_y.push_back(ry);
  }
  void reserve(size_t n) {
    left_x.reserve(n), left_y.reserve(n), right_x.reserve(n), right_y.reserve(n);
  }
};

/// One motion between two images, in pixels: a fundamental matrix (x_r^T F x_l = 0) or a
/// homography (x_r ~ H x_l).
struct TwoViewModel {
  bool homography = false;
  Eigen::Matrix3d matrix = Eigen::Matrix3d::Zero();
};

/// The model's residual of one pair, px: for F the larger distance of either point to its
/// epipolar line (as epipolarDistances(...).max()), for H the larger transfer error of the two
/// directions. Infinite when undefined.
double modelResidual(const TwoViewModel& model, double lx, double ly, double rx, double ry);

/// The model's matrix (`matrix`) and, for a homography, its inverse (`inverse`; zeros for F) as
/// row-major floats: what the float residual kernels take.
void modelFloats(const TwoViewModel& model, float matrix[9], float inverse[9]);

/// Squared residuals of every pair (float, as modelResidual squared), into `out`.
void squaredResiduals(const TwoViewModel& model, const PointPairs& pairs, std::vector<float>* out);
/// The same for the pairs [begin, end) only, written to out[begin, end).
void squaredResiduals(const TwoViewModel& model, const PointPairs& pairs, size_t begin, size_t end,
                      float* out);

/// Fundamental matrices through 7 correspondences (rows of the 7x2 arrays; best normalised, as
/// Hartley's), from the cubic det(a F1 + (1 - a) F2) = 0: up to three, none for a degenerate
/// sample.
std::vector<Eigen::Matrix3d> sevenPointFundamental(const Eigen::Matrix<double, 7, 2>& left,
                                                   const Eigen::Matrix<double, 7, 2>& right);
/// The homography through 4 correspondences (DLT); false for a degenerate sample.
bool fourPointHomography(const Eigen::Matrix<double, 4, 2>& left,
                         const Eigen::Matrix<double, 4, 2>& right, Eigen::Matrix3d* H);

/// Least squares over n >= 8 (F) or n >= 4 (H) weighted correspondences (n x 2 arrays): the
/// smallest eigenvector of the algebraic normal equations; F made rank 2. False when degenerate
/// or when the three sizes differ.
/// `start`, a model near the answer, makes it a few steps of inverse iteration.
bool leastSquaresFundamental(const Eigen::MatrixX2d& left, const Eigen::MatrixX2d& right,
                             const Eigen::VectorXd& weights, Eigen::Matrix3d* F,
                             const Eigen::Matrix3d* start = nullptr);
bool leastSquaresHomography(const Eigen::MatrixX2d& left, const Eigen::MatrixX2d& right,
                            const Eigen::VectorXd& weights, Eigen::Matrix3d* H,
                            const Eigen::Matrix3d* start = nullptr);

/// Hartley's normalisation of one image's points, made robust: the median point to the origin,
/// the median distance from it sqrt(2) (medians of at most 255 points evenly spread over the
/// list).
/// Returns T with x_normalised = T x.
Eigen::Matrix3d hartleyNormalisation(const std::vector<float>& x, const std::vector<float>& y);

/// Settings of one robust fit (LO-RANSAC with a truncated quadratic score).
struct TwoViewFitSettings {
  bool homography = false;
  double max_residual_px = 1.0;  ///< inlier threshold: modelResidual <= this
  double confidence = 0.99;
  int max_iterations = 1000;
  /// Local samples (NAPSAC): one match drawn at random and the rest of the sample drawn among
  /// its 4 m nearest in the left image, so that a sample stays on one object where several move
  /// differently.
  bool local_samples = false;
  /// The local optimisation runs only when the best hypothesis has at least this many inliers
  /// among `sample_from` (a model that cannot win the comparison it is fitted for is left as is).
  size_t min_inliers_to_refine = 0;
};

/// The result of a fit: the model, its inliers among the pairs fitted (by index), the iterations.
struct TwoViewFit {
  bool found = false;
  TwoViewModel model;
  std::vector<int> inliers;
  double cost = 0.0;  ///< the truncated quadratic over all pairs, px^2 (lower is better)
  int iterations = 0;
};

/// LO-RANSAC over the pairs: minimal samples drawn from `sample_from` (distinct indices into
/// pairs, as many as a sample at least; all pairs when empty) with `random`, each hypothesis
/// scored over all pairs by the truncated quadratic (MSAC), stopping when `confidence` says an
/// all-inlier sample was drawn (the inlier share of `sample_from`) or at max_iterations. Each new
/// best is refined once by least squares over the pairs within twice the threshold, Tukey-weighted
/// by their residuals (times the Sampson weight for F), and its refined support sets the count;
/// the final best also by least squares over 5 random subsets of 4 m of those pairs (a
/// fundamental matrix whose epipole lies among the points, or a homography across two close
/// motions, can be its own least-squares fixed point), then reweighted while the score improves.
TwoViewFit fitTwoViewModel(const PointPairs& pairs, const std::vector<int>& sample_from,
                           const TwoViewFitSettings& settings, std::mt19937* random);

/// A finished model refined against `pairs` (e.g. the putatives near it, where the fit saw a
/// sample of them): Tukey-reweighted least squares over those within twice max_residual_px (at
/// most 4096, evenly spread), while the truncated quadratic over `pairs` improves. The model
/// itself when nothing improves it (also for NaN models and fewer than 8 pairs for F, 4 for H).
TwoViewModel polishTwoViewModel(const PointPairs& pairs, const TwoViewModel& model,
                                double max_residual_px);

/// The RANSAC iteration count for an inlier share w and sample size m at `confidence`, capped.
int ransacIterations(double w, int m, double confidence, int cap);

}  // namespace sift_hull
