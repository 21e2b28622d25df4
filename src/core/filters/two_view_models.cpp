#include "sift_hull/filters/two_view_models.h"

#include <Eigen/Dense>
#include <algorithm>
#include <cmath>
#include <cstring>
#include <limits>
#include <vector>

namespace sift_hull {
namespace {

using Vector9d = Eigen::Matrix<double, 9, 1>;
using Matrix9d = Eigen::Matrix<double, 9, 9>;

Eigen::Matrix3d fromRowMajor(const Vector9d& f) {
  Eigen::Matrix3d M;
  M << f(0), f(1), f(2), f(3), f(4), f(5), f(6), f(7), f(8);
  return M;
}

/// The row of x_r^T F x_l = 0 in F's nine row-major entries.
Vector9d epipolarRow(double lx, double ly, double rx, double ry) {
  Vector9d a;
  a << rx * lx, rx * ly, rx, ry * lx, ry * ly, ry, lx, ly, 1.0;
  return a;
}

/// The two DLT rows of r ~ H l in H's nine row-major entries.
void homographyRows(double lx, double ly, double rx, double ry, Vector9d* a, Vector9d* b) {
  *a << -lx, -ly, -1.0, 0.0, 0.0, 0.0, rx * lx, rx * ly, rx;
  *b << 0.0, 0.0, 0.0, -lx, -ly, -1.0, ry * lx, ry * ly, ry;
}

/// An orthonormal basis of the null space of a Rows x 9 matrix of rank Rows (7 or 8 rows):
/// Gauss-Jordan elimination with full pivoting to [I | B] (columns permuted), one vector per
/// free column, then Gram-Schmidt (so that a nearly degenerate sample does not give two nearly
/// parallel vectors). False when a pivot falls below 1e-10 of the first (rank below Rows:
/// collinear or repeated points) or is not finite.
template <int Rows>
bool nullSpace(Eigen::Matrix<double, Rows, 9> A, Eigen::Matrix<double, 9, 9 - Rows>* basis) {
  int column[9];
  for (int k = 0; k < 9; ++k) column[k] = k;
  double first = 0.0;
  for (int k = 0; k < Rows; ++k) {
    Eigen::Index r = 0, c = 0;
    const double pivot = A.bottomRightCorner(Rows - k, 9 - k).cwiseAbs().maxCoeff(&r, &c);
    if (k == 0) first = pivot;
    if (!(pivot > 1e-10 * first) || !std::isfinite(pivot)) return false;
    r += k, c += k;
    A.row(k).swap(A.row(r));
    A.col(k).swap(A.col(c));
    std::swap(column[k], column[c]);
    A.row(k) /= A(k, k);
    for (int i = 0; i < Rows; ++i) {
      if (i != k) A.row(i) -= A(i, k) * A.row(k);
    }
  }
  for (int j = 0; j < 9 - Rows; ++j) {
    Vector9d x = Vector9d::Zero();
    for (int i = 0; i < Rows; ++i) x(column[i]) = -A(i, Rows + j);
    x(column[Rows + j]) = 1.0;
    for (int k = 0; k < j; ++k) x -= basis->col(k).dot(x) * basis->col(k);
    basis->col(j) = x / x.norm();
  }
  return true;
}

/// Real roots of c3 x^3 + c2 x^2 + c1 x + c0, each polished by two Newton steps.
std::vector<double> realCubicRootsOf(double c3, double c2, double c1, double c0) {
  std::vector<double> roots;
  roots.reserve(3);
  const double largest = std::max({std::abs(c3), std::abs(c2), std::abs(c1), std::abs(c0)});
  if (!(largest > 0.0) || !std::isfinite(largest)) return roots;
  if (std::abs(c3) < 1e-12 * largest) {  // quadratic
    if (std::abs(c2) < 1e-12 * largest) {
      if (std::abs(c1) > 0.0) roots.push_back(-c0 / c1);
      return roots;
    }
    const double disc = c1 * c1 - 4.0 * c2 * c0;
    if (disc < 0.0) return roots;
    const double q = -0.5 * (c1 + std::copysign(std::sqrt(disc), c1));
    roots.push_back(q / c2);
    if (q != 0.0) roots.push_back(c0 / q);
  } else {
    const double b = c2 / c3, c = c1 / c3, d = c0 / c3;
    const double q = (b * b - 3.0 * c) / 9.0, r = (2.0 * b * b * b - 9.0 * b * c + 27.0 * d) / 54.0;
    if (r * r < q * q * q) {
      const double theta = std::acos(std::clamp(r / std::sqrt(q * q * q), -1.0, 1.0));
      const double s = -2.0 * std::sqrt(q);
      for (int k = 0; k < 3; ++k)
        roots.push_back(s * std::cos((theta + 2.0 * M_PI * k) / 3.0) - b / 3.0);
    } else {
      const double a = -std::copysign(std::cbrt(std::abs(r) + std::sqrt(r * r - q * q * q)), r);
      roots.push_back(a + (a == 0.0 ? 0.0 : q / a) - b / 3.0);
    }
  }
  for (double& x : roots) {
    for (int step = 0; step < 2; ++step) {
      const double f = ((c3 * x + c2) * x + c1) * x + c0, df = (3.0 * c3 * x + 2.0 * c2) * x + c1;
      if (df != 0.0) x -= f / df;
    }
  }
  return roots;
}

/// Whether three points are (nearly) on one line, relative to their spread.
bool collinear(const Eigen::Vector2d& a, const Eigen::Vector2d& b, const Eigen::Vector2d& c) {
  const Eigen::Vector2d u = b - a, v = c - a;
  const double area = std::abs(u.x() * v.y() - u.y() * v.x());
  return area <= 1e-9 * std::max(1e-300, u.squaredNorm() + v.squaredNorm());
}

bool anyThreeCollinear(const Eigen::Matrix<double, 4, 2>& p) {
  for (int skip = 0; skip < 4; ++skip) {
    int k[3], n = 0;
    for (int i = 0; i < 4; ++i) {
      if (i != skip) k[n++] = i;
    }
    if (collinear(p.row(k[0]).transpose(), p.row(k[1]).transpose(), p.row(k[2]).transpose())) {
      return true;
    }
  }
  return false;
}

constexpr int kInverseIterations = 4;

/// Eight doubles: one vector register with AVX-512, split by the compiler where narrower.
typedef double Lanes __attribute__((vector_size(64)));

/// The six products of (x, y, 1) with itself: x x, x y, x, y y, y, 1 (index of entry pair (i, k)
/// of (x, y, 1), i <= k, by kMonomial).
constexpr int kMonomial[3][3] = {{0, 1, 2}, {1, 3, 4}, {2, 4, 5}};

/// sums[p][q] = sum_i w_i R_p(i) L_q(i) for the six monomials R of the right points and L of the
/// left ones (both listed as kMonomial does), over n points: each lane of eight sums its own rows
/// (8 k + lane), then the lanes and the remaining rows are added in a fixed order, so that the
/// result does not depend on the vector width the CPU has.
__attribute__((target_clones("arch=x86-64-v4", "arch=x86-64-v3", "default"))) void monomialSums(
    const double* lx, const double* ly, const double* rx, const double* ry, const double* w,
    size_t n, double (*sums)[6]) {
  const size_t whole = n / 8 * 8;
  for (int half = 0; half < 2; ++half) {  // three right monomials at a time: 18 accumulators
    Lanes acc[3][6] = {};
    for (size_t i = 0; i < whole; i += 8) {
      Lanes x, y, u, v, wi;  // through memcpy: the arrays need not be aligned to 64 bytes
      std::memcpy(&x, lx + i, sizeof x), std::memcpy(&y, ly + i, sizeof y);
      std::memcpy(&u, rx + i, sizeof u), std::memcpy(&v, ry + i, sizeof v);
      std::memcpy(&wi, w + i, sizeof wi);
      const Lanes left[5] = {x * x, x * y, x, y * y, y};  // and 1: acc[p][5]
      const Lanes wu = wi * u, wv = wi * v;
      const Lanes all_right[6] = {wu * u, wu * v, wu, wv * v, wv, wi};
      for (int p = 0; p < 3; ++p) {
        const Lanes right = all_right[3 * half + p];
        for (int q = 0; q < 5; ++q) acc[p][q] += right * left[q];
        acc[p][5] += right;
      }
    }
    for (int p = 0; p < 3; ++p) {
      for (int q = 0; q < 6; ++q) {
        double total = 0.0;
        for (int lane = 0; lane < 8; ++lane) total += acc[p][q][lane];
        sums[3 * half + p][q] = total;
      }
    }
  }
  for (size_t i = whole; i < n; ++i) {
    const double left[6] = {lx[i] * lx[i], lx[i] * ly[i], lx[i], ly[i] * ly[i], ly[i], 1.0};
    const double wu = w[i] * rx[i], wv = w[i] * ry[i];
    const double right[6] = {wu * rx[i], wu * ry[i], wu, wv * ry[i], wv, w[i]};
    for (int p = 0; p < 6; ++p) {
      for (int q = 0; q < 6; ++q) sums[p][q] += right[p] * left[q];
    }
  }
}

/// sum_i w_i a_i a_i^T for the rows a = (rx lx, rx ly, rx, ry lx, ry ly, ry, lx, ly, 1) of
/// x_r^T F x_l = 0 (F's nine row-major entries; also the columns homographyNormal combines), n
/// correspondences (n x 2 arrays, column-major) with their weights. a is r (x) l for r = (rx, ry,
/// 1) and l = (lx, ly, 1), so entry (3 i + j, 3 k + m) is sum w r_i r_k l_j l_m: 36 sums of
/// monomials give all 81 entries.
Matrix9d epipolarGram(const Eigen::MatrixX2d& left, const Eigen::MatrixX2d& right,
                      const Eigen::VectorXd& weights) {
  double sums[6][6];
  monomialSums(left.col(0).data(), left.col(1).data(), right.col(0).data(), right.col(1).data(),
               weights.data(), size_t(left.rows()), sums);
  Matrix9d G;
  for (int i = 0; i < 3; ++i) {
    for (int j = 0; j < 3; ++j) {
      for (int k = 0; k < 3; ++k) {
        for (int m = 0; m < 3; ++m)
          G(3 * i + j, 3 * k + m) = sums[kMonomial[i][k]][kMonomial[j][m]];
      }
    }
  }
  return G;
}

/// The eigenvector of the smallest eigenvalue of a normal matrix: by inverse iteration from
/// `start` (a model near the answer, row-major) when given, which is a few 9x9 solves instead of
/// a full eigendecomposition, else (or when that fails) by the eigensolver.
Vector9d smallestEigenvector(const Matrix9d& normal, const Eigen::Matrix3d* start) {
  if (start != nullptr) {
    const Eigen::LDLT<Matrix9d> ldlt(normal);
    const Eigen::VectorXd pivots = ldlt.vectorD().cwiseAbs();
    // A zero pivot (exactly consistent points) is solved as zero: the eigensolver then.
    const bool usable = pivots.minCoeff() > 1e-15 * pivots.maxCoeff();
    Vector9d x;
    for (int k = 0; k < 9; ++k) x(k) = (*start)(k / 3, k % 3);
    for (int step = 0; usable && step < kInverseIterations && ldlt.info() == Eigen::Success;
         ++step) {
      x = ldlt.solve(x);
      x /= x.norm();
    }
    if (usable && ldlt.info() == Eigen::Success && x.allFinite()) return x;
  }
  Eigen::SelfAdjointEigenSolver<Matrix9d> solver(normal);
  return solver.eigenvectors().col(0);
}

/// The normal matrix of the two DLT rows of r ~ H l per correspondence, a = [-l, 0, u l] and
/// b = [0, -l, v l] (l = (x, y, 1), r = (u, v)), from the Gram matrix G of the epipolar rows'
/// columns [u l, v l, l] (one row per correspondence instead of two): sum w (a a^T + b b^T) has
/// the blocks G_ll, G_ll on the diagonal, -G_l(ul), -G_l(vl) beside and G_(ul)(ul) + G_(vl)(vl)
/// last.
Matrix9d homographyNormal(const Matrix9d& G) {
  Matrix9d N = Matrix9d::Zero();
  const auto ll = G.block<3, 3>(6, 6);
  N.block<3, 3>(0, 0) = ll, N.block<3, 3>(3, 3) = ll;
  N.block<3, 3>(0, 6) = -G.block<3, 3>(6, 0), N.block<3, 3>(3, 6) = -G.block<3, 3>(6, 3);
  N.block<3, 3>(6, 0) = N.block<3, 3>(0, 6).transpose();
  N.block<3, 3>(6, 3) = N.block<3, 3>(3, 6).transpose();
  N.block<3, 3>(6, 6) = G.block<3, 3>(0, 0) + G.block<3, 3>(3, 3);
  return N;
}

/// The nearest matrix of rank two (Frobenius): F (I - v v^T) for v the right singular vector of
/// F's smallest singular value, the eigenvector of F^T F's smallest eigenvalue, from the closed
/// form for 3x3 (which is what truncating the SVD gives, at a fraction of a Jacobi SVD's cost).
Eigen::Matrix3d rankTwo(const Eigen::Matrix3d& F) {
  Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> eigen;
  eigen.computeDirect(F.transpose() * F);
  const Eigen::Vector3d v = eigen.eigenvectors().col(0);
  return F - (F * v) * v.transpose();
}

bool finiteMatrix(const Eigen::Matrix3d& M) { return M.allFinite() && M.norm() > 0.0; }

__attribute__((target_clones("arch=x86-64-v4", "arch=x86-64-v3", "default"))) void
fundamentalResiduals(const float* m, const float* lx, const float* ly, const float* rx,
                     const float* ry, size_t n, float* out) {
  for (size_t i = 0; i < n; ++i) {
    const float a = m[0] * lx[i] + m[1] * ly[i] + m[2];
    const float b = m[3] * lx[i] + m[4] * ly[i] + m[5];
    const float c = m[6] * lx[i] + m[7] * ly[i] + m[8];
    const float d = m[0] * rx[i] + m[3] * ry[i] + m[6];
    const float e = m[1] * rx[i] + m[4] * ry[i] + m[7];
    const float error = rx[i] * a + ry[i] * b + c;
    const float r2 = error * error / std::min(a * a + b * b, d * d + e * e);
    out[i] = r2 == r2 ? r2 : std::numeric_limits<float>::infinity();  // NaN: undefined
  }
}

__attribute__((target_clones("arch=x86-64-v4", "arch=x86-64-v3", "default"))) void
homographyResiduals(const float* h, const float* g, const float* lx, const float* ly,
                    const float* rx, const float* ry, size_t n, float* out) {
  for (size_t i = 0; i < n; ++i) {
    const float w = h[6] * lx[i] + h[7] * ly[i] + h[8];
    const float u = (h[0] * lx[i] + h[1] * ly[i] + h[2]) / w - rx[i];
    const float v = (h[3] * lx[i] + h[4] * ly[i] + h[5]) / w - ry[i];
    const float wb = g[6] * rx[i] + g[7] * ry[i] + g[8];
    const float ub = (g[0] * rx[i] + g[1] * ry[i] + g[2]) / wb - lx[i];
    const float vb = (g[3] * rx[i] + g[4] * ry[i] + g[5]) / wb - ly[i];
    const float forward = u * u + v * v, backward = ub * ub + vb * vb;
    const float inf = std::numeric_limits<float>::infinity();
    out[i] = std::max(forward == forward ? forward : inf, backward == backward ? backward : inf);
  }
}

/// The same, well conditioned when c3 is small beside c0: then the roots of the reversed cubic
/// c0 y^3 + c1 y^2 + c2 y + c3 in y = 1 / x (whose leading coefficient is the larger end).
std::vector<double> realCubicRoots(double c3, double c2, double c1, double c0) {
  if (std::abs(c3) >= std::abs(c0)) return realCubicRootsOf(c3, c2, c1, c0);
  std::vector<double> roots;
  for (double y : realCubicRootsOf(c0, c1, c2, c3)) {
    if (y != 0.0 && std::isfinite(1.0 / y)) roots.push_back(1.0 / y);
  }
  return roots;
}

}  // namespace

double modelResidual(const TwoViewModel& model, double lx, double ly, double rx, double ry) {
  const Eigen::Matrix3d& M = model.matrix;
  const Eigen::Vector3d l(lx, ly, 1.0), r(rx, ry, 1.0);
  if (!model.homography) {
    const Eigen::Vector3d line_r = M * l, line_l = M.transpose() * r;
    const double e = std::abs(r.dot(line_r));
    const double n = std::min(line_r.head<2>().squaredNorm(), line_l.head<2>().squaredNorm());
    return n > 0.0 ? e / std::sqrt(n) : std::numeric_limits<double>::infinity();
  }
  const Eigen::Vector3d forward = M * l, backward = M.inverse() * r;
  const double f = (forward.hnormalized() - r.head<2>()).norm();
  const double b = (backward.hnormalized() - l.head<2>()).norm();
  return std::isfinite(f) && std::isfinite(b) ? std::max(f, b)
                                              : std::numeric_limits<double>::infinity();
}

void modelFloats(const TwoViewModel& model, float matrix[9], float inverse[9]) {
  const Eigen::Matrix3d inverted =
      model.homography ? Eigen::Matrix3d(model.matrix.inverse()) : Eigen::Matrix3d::Zero();
  for (int k = 0; k < 9; ++k) {
    matrix[k] = static_cast<float>(model.matrix(k / 3, k % 3));
    inverse[k] = static_cast<float>(inverted(k / 3, k % 3));
  }
}

void squaredResiduals(const TwoViewModel& model, const PointPairs& pairs, std::vector<float>* out) {
  out->resize(pairs.size());
  squaredResiduals(model, pairs, 0, pairs.size(), out->data());
}

void squaredResiduals(const TwoViewModel& model, const PointPairs& pairs, size_t begin, size_t end,
                      float* out) {
  end = std::min(end, pairs.size());
  if (begin >= end) return;
  float m[9], g[9];
  modelFloats(model, m, g);
  const size_t n = end - begin;
  const float *lx = pairs.left_x.data() + begin, *ly = pairs.left_y.data() + begin;
  const float *rx = pairs.right_x.data() + begin, *ry = pairs.right_y.data() + begin;
  if (model.homography) {
    homographyResiduals(m, g, lx, ly, rx, ry, n, out + begin);
  } else {
    fundamentalResiduals(m, lx, ly, rx, ry, n, out + begin);
  }
}

std::vector<Eigen::Matrix3d> sevenPointFundamental(const Eigen::Matrix<double, 7, 2>& left,
                                                   const Eigen::Matrix<double, 7, 2>& right) {
  Eigen::Matrix<double, 7, 9> A;
  for (int i = 0; i < 7; ++i)
    A.row(i) = epipolarRow(left(i, 0), left(i, 1), right(i, 0), right(i, 1)).transpose();
  Eigen::Matrix<double, 9, 2> null;
  if (!nullSpace<7>(A, &null)) return {};  // collinear or repeated points
  const Eigen::Matrix3d F1 = fromRowMajor(null.col(0)), F2 = fromRowMajor(null.col(1));
  // det(a F1 + (1 - a) F2) = c3 a^3 + c2 a^2 + c1 a + c0, from its values at 0, 1, -1 and 2.
  const double d0 = F2.determinant(), d1 = F1.determinant();
  const double dm = (2.0 * F2 - F1).determinant(), d2 = (2.0 * F1 - F2).determinant();
  const double c0 = d0, c2 = 0.5 * (d1 + dm) - d0, odd = 0.5 * (d1 - dm);  // odd = c3 + c1
  const double c3 = (d2 - c0 - 4.0 * c2 - 2.0 * odd) / 6.0, c1 = odd - c3;
  std::vector<Eigen::Matrix3d> solutions;
  solutions.reserve(3);
  for (double a : realCubicRoots(c3, c2, c1, c0)) {
    const Eigen::Matrix3d F = a * F1 + (1.0 - a) * F2;
    if (finiteMatrix(F)) solutions.push_back(F / F.norm());
  }
  return solutions;
}

bool fourPointHomography(const Eigen::Matrix<double, 4, 2>& left,
                         const Eigen::Matrix<double, 4, 2>& right, Eigen::Matrix3d* H) {
  if (anyThreeCollinear(left) || anyThreeCollinear(right)) return false;
  Eigen::Matrix<double, 8, 9> A;
  for (int i = 0; i < 4; ++i) {
    Vector9d a, b;
    homographyRows(left(i, 0), left(i, 1), right(i, 0), right(i, 1), &a, &b);
    A.row(2 * i) = a.transpose(), A.row(2 * i + 1) = b.transpose();
  }
  Eigen::Matrix<double, 9, 1> null;
  if (!nullSpace<8>(A, &null)) return false;
  *H = fromRowMajor(null.col(0));
  return finiteMatrix(*H) && std::abs(H->determinant()) > 1e-12 * std::pow(H->norm(), 3);
}

bool leastSquaresFundamental(const Eigen::MatrixX2d& left, const Eigen::MatrixX2d& right,
                             const Eigen::VectorXd& weights, Eigen::Matrix3d* F,
                             const Eigen::Matrix3d* start) {
  if (left.rows() < 8 || right.rows() != left.rows() || weights.size() != left.rows()) return false;
  *F = rankTwo(fromRowMajor(smallestEigenvector(epipolarGram(left, right, weights), start)));
  return finiteMatrix(*F);
}

bool leastSquaresHomography(const Eigen::MatrixX2d& left, const Eigen::MatrixX2d& right,
                            const Eigen::VectorXd& weights, Eigen::Matrix3d* H,
                            const Eigen::Matrix3d* start) {
  if (left.rows() < 4 || right.rows() != left.rows() || weights.size() != left.rows()) return false;
  *H = fromRowMajor(
      smallestEigenvector(homographyNormal(epipolarGram(left, right, weights)), start));
  return finiteMatrix(*H) && std::abs(H->determinant()) > 1e-12 * std::pow(H->norm(), 3);
}

Eigen::Matrix3d hartleyNormalisation(const std::vector<float>& x, const std::vector<float>& y) {
  // Medians rather than means, so that one point far away (a hostile 1e30) does not squeeze all
  // the others onto the origin; of at most kMedianSample points evenly spread over the list,
  // which is as good a normalisation (it only conditions the least squares) and keeps its cost
  // fixed and small: a fit normalises its pairs several times.
  constexpr size_t kMedianSample = 63;
  const size_t n = std::min(x.size(), y.size()), count = std::min(n, kMedianSample);
  std::vector<double> xs(count), ys(count);
  for (size_t k = 0; k < count; ++k) {
    const size_t i = k * n / count;
    xs[k] = x[i], ys[k] = y[i];
  }
  auto median = [](std::vector<double> values) {
    if (values.empty()) return 0.0;
    const auto middle = values.begin() + values.size() / 2;
    std::nth_element(values.begin(), middle, values.end());
    return *middle;
  };
  const double cx = median(xs), cy = median(ys);
  std::vector<double> distances(count);
  for (size_t k = 0; k < count; ++k) {
    const double dx = xs[k] - cx, dy = ys[k] - cy;
    distances[k] = std::sqrt(dx * dx + dy * dy);
  }
  double spread = median(distances);
  if (!(spread > 0.0)) {  // most points at one place: their mean distance, else no scaling
    double sum = 0.0;
    for (double d : distances) sum += d;
    spread = distances.empty() ? 0.0 : sum / double(distances.size());
  }
  const double s = spread > 0.0 && std::isfinite(spread) ? std::sqrt(2.0) / spread : 1.0;
  Eigen::Matrix3d T;
  T << s, 0.0, -s * cx, 0.0, s, -s * cy, 0.0, 0.0, 1.0;
  return T;
}

int ransacIterations(double w, int m, double confidence, int cap) {
  if (!(w > 0.0)) return cap;  // also NaN
  const double all_inliers = std::pow(std::clamp(w, 0.0, 1.0), m);
  if (all_inliers <= 0.0) return cap;
  if (all_inliers >= 1.0) return 1;
  const double needed = std::log(1.0 - confidence) / std::log1p(-all_inliers);
  return static_cast<int>(std::clamp(std::ceil(needed), 1.0, double(cap)));
}

}  // namespace sift_hull
