#include "sift_hull/hull/bounding_box.h"

#include <glpk.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <csetjmp>
#include <opencv2/imgproc.hpp>
#include <string>
#include <vector>

#include "sift_hull/geometry/camera_set.h"

namespace sift_hull {
namespace {

// A box coordinate this many times farther out than the farthest camera centre is not a bound:
// near-parallel cones give finite but meaningless optima of that size.
constexpr double kFarCoordinateFactor = 1e6;
// A box edge below this fraction of the cameras' spread is no volume (rounding of the LP).
constexpr double kMinRelativeExtent = 1e-9;

constexpr char kUnboundedHint[] =
    "the views' rays are nearly parallel or silhouettes touch the image border; add views from "
    "other directions or give the box yourself";
constexpr char kEmptyHint[] =
    "the viewing cones of the silhouettes do not intersect: check the calibration and the "
    "silhouettes";

/// The half-space coefficients.dot(X) >= lower_bound.
struct HalfSpace {
  Eigen::Vector3d coefficients;
  double lower_bound;
};

/// The half-space row.dot([X; 1]) >= 0, scaled to unit-norm coefficients of x, y, z so that the
/// rows of every view weigh alike in the simplex tolerances.
HalfSpace unitHalfSpace(const Eigen::Vector4d& row) {
  const double norm = row.head<3>().norm();
  return {row.head<3>() / norm, -row(3) / norm};
}

/// The paper's eq. 8 for one view, linear in X through the depth w = p3 . [X; 1]:
/// u_min w <= p1 . [X; 1] <= u_max w and v_min w <= p2 . [X; 1] <= v_max w, bounded sides only,
/// plus w >= 0 so that the cone's mirror image behind the camera is not taken in.
void appendViewHalfSpaces(const PinholeCamera& camera, const SilhouetteBounds& bounds,
                          std::vector<HalfSpace>* half_spaces) {
  const Matrix34d P = camera.projectionMatrix();
  const Eigen::Vector4d p1 = P.row(0).transpose();
  const Eigen::Vector4d p2 = P.row(1).transpose();
  const Eigen::Vector4d p3 = P.row(2).transpose();
  if (bounds.has_u_min) half_spaces->push_back(unitHalfSpace(p1 - bounds.u_min_px * p3));
  if (bounds.has_u_max) half_spaces->push_back(unitHalfSpace(bounds.u_max_px * p3 - p1));
  if (bounds.has_v_min) half_spaces->push_back(unitHalfSpace(p2 - bounds.v_min_px * p3));
  if (bounds.has_v_max) half_spaces->push_back(unitHalfSpace(bounds.v_max_px * p3 - p2));
  half_spaces->push_back(unitHalfSpace(p3));
}

std::string viewName(const std::vector<std::string>& names, size_t view) {
  return names.empty() ? "view " + std::to_string(view) : names[view];
}

bool boundsAreFinite(const SilhouetteBounds& bounds) {
  return std::isfinite(bounds.u_min_px) && std::isfinite(bounds.u_max_px) &&
         std::isfinite(bounds.v_min_px) && std::isfinite(bounds.v_max_px);
}

/// Throws for mismatched sizes, empty silhouettes and fewer than two views that bound anything.
void checkViews(const std::vector<PinholeCamera>& cameras,
                const std::vector<SilhouetteBounds>& bounds,
                const std::vector<std::string>& names) {
  if (cameras.size() != bounds.size()) {
    throw std::invalid_argument("hullBoundingBox: " + std::to_string(cameras.size()) +
                                " cameras but " + std::to_string(bounds.size()) + " bounds");
  }
  if (!names.empty() && names.size() != cameras.size()) {
    throw std::invalid_argument("hullBoundingBox: " + std::to_string(names.size()) + " names for " +
                                std::to_string(cameras.size()) + " views");
  }
  int bounding_views = 0;
  for (size_t i = 0; i < bounds.size(); ++i) {
    if (bounds[i].empty) {
      throw HullBoxError(HullBoxError::Reason::kEmpty,
                         "the silhouette of " + viewName(names, i) + " is empty");
    }
    if (!boundsAreFinite(bounds[i]) || !(bounds[i].u_min_px <= bounds[i].u_max_px) ||
        !(bounds[i].v_min_px <= bounds[i].v_max_px)) {
      throw std::invalid_argument("the silhouette bounds of " + viewName(names, i) +
                                  " are not finite or not ordered (min <= max)");
    }
    if (!cameras[i].projectionMatrix().allFinite() || !cameras[i].centre().allFinite()) {
      throw std::invalid_argument("the camera of " + viewName(names, i) +
                                  " has a projection beyond double precision");
    }
    if (bounds[i].boundedSides() > 0) ++bounding_views;
  }
  if (bounding_views < 2) {
    throw HullBoxError(HullBoxError::Reason::kTooFewViews,
                       std::to_string(bounding_views) +
                           " view(s) with a bounded silhouette side; at least two are needed");
  }
}

/// The half-spaces in a frame around the cameras, X = origin + scale X': the simplex's
/// tolerances are absolute, so coordinates far from the world origin (a map frame) or of another
/// unit (millimetres) would otherwise blunt them.
struct LpFrame {
  Eigen::Vector3d origin = Eigen::Vector3d::Zero();
  double scale = 1.0;
};

LpFrame frameOfCameras(const std::vector<PinholeCamera>& cameras) {
  LpFrame frame;
  for (const PinholeCamera& camera : cameras) frame.origin += camera.centre() / cameras.size();
  double sum_squares = 0.0;
  for (const PinholeCamera& camera : cameras) {
    sum_squares += (camera.centre() - frame.origin).squaredNorm() / cameras.size();
  }
  const double rms = std::sqrt(sum_squares);
  if (rms > 0.0 && std::isfinite(rms)) frame.scale = rms;
  return frame;
}

HalfSpace toFrame(const HalfSpace& half_space, const LpFrame& frame) {
  // a.X >= b with X = o + s X' and |a| = 1: a.X' >= (b - a.o) / s.
  return {half_space.coefficients,
          (half_space.lower_bound - half_space.coefficients.dot(frame.origin)) / frame.scale};
}

/// What one GLPK session found: per axis and direction (x min, x max, y min, ...) the GLPK
/// return code, status and optimum.
struct LpSolution {
  bool aborted = false;  ///< GLPK called its error hook (a failed internal assertion)
  int return_codes[6] = {0, 0, 0, 0, 0, 0};
  int statuses[6] = {0, 0, 0, 0, 0, 0};
  double optima[6] = {0, 0, 0, 0, 0, 0};
};

/// Simplex iterations and milliseconds one solve may take: three unknowns need a few dozen
/// iterations, so reaching either means GLPK is cycling on degenerate input.
constexpr int kIterationLimit = 10000;
constexpr int kTimeLimit_ms = 5000;

/// GLPK's error hook: GLPK's memory of this thread is freed and control returns to the setjmp
/// in solveBoxLp, instead of GLPK calling abort().
extern "C" void glpkErrorHook(void* jump) {
  glp_free_env();
  std::longjmp(*static_cast<std::jmp_buf*>(jump), 1);
}

/// Fills the problem: columns 1..3 are the free variables x, y, z; one row per half-space.
void fillProblem(const HalfSpace* half_spaces, int rows, glp_prob* problem) {
  glp_add_cols(problem, 3);
  for (int column = 1; column <= 3; ++column) glp_set_col_bnds(problem, column, GLP_FR, 0.0, 0.0);
  glp_add_rows(problem, rows);
  const int columns[4] = {0, 1, 2, 3};  // GLPK arrays start at index 1
  for (int i = 0; i < rows; ++i) {
    const Eigen::Vector3d& a = half_spaces[i].coefficients;
    const double values[4] = {0.0, a.x(), a.y(), a.z()};
    glp_set_mat_row(problem, i + 1, 3, columns, values);
    glp_set_row_bnds(problem, i + 1, GLP_LO, half_spaces[i].lower_bound, 0.0);
  }
}

/// The six extremes of x, y, z over the half-spaces, in one GLPK session that leaves no GLPK
/// memory behind (glp_free_env: GLPK keeps an environment per thread otherwise). Holds only
/// trivially destructible locals, so that the error hook's longjmp skips no destructor.
void solveBoxLp(const HalfSpace* half_spaces, int rows, LpSolution* solution) {
  std::jmp_buf jump;
  if (setjmp(jump) != 0) {  // GLPK failed an assertion; glpkErrorHook freed its memory
    glp_error_hook(nullptr, nullptr);
    solution->aborted = true;
    return;
  }
  glp_error_hook(glpkErrorHook, &jump);
  glp_term_out(GLP_OFF);
  glp_prob* problem = glp_create_prob();
  fillProblem(half_spaces, rows, problem);
  glp_smcp parameters;
  glp_init_smcp(&parameters);
  parameters.msg_lev = GLP_MSG_OFF;
  parameters.presolve = GLP_OFF;
  parameters.it_lim = kIterationLimit;
  parameters.tm_lim = kTimeLimit_ms;
  for (int k = 0; k < 6; ++k) {
    const int column = k / 2 + 1;
    for (int j = 1; j <= 3; ++j) glp_set_obj_coef(problem, j, j == column ? 1.0 : 0.0);
    glp_set_obj_dir(problem, k % 2 == 0 ? GLP_MIN : GLP_MAX);
    solution->return_codes[k] = glp_simplex(problem, &parameters);
    solution->statuses[k] = glp_get_status(problem);
    solution->optima[k] = glp_get_col_prim(problem, column);
  }
  glp_delete_prob(problem);
  glp_error_hook(nullptr, nullptr);
  glp_free_env();
}

double farCoordinateLimit(const std::vector<PinholeCamera>& cameras, const LpFrame& frame) {
  double farthest_centre = 1.0;
  for (const PinholeCamera& camera : cameras) {
    farthest_centre =
        std::max(farthest_centre, (camera.centre() - frame.origin).norm() / frame.scale);
  }
  return kFarCoordinateFactor * farthest_centre;
}

[[noreturn]] void throwUnbounded(const char* axis_name, bool minimum, const std::string& detail) {
  const std::string side = minimum ? "minimum" : "maximum";
  throw HullBoxError(HullBoxError::Reason::kUnbounded, "the bounding box has no finite " + side +
                                                           " " + axis_name + " (" + detail +
                                                           "): " + kUnboundedHint);
}

/// Extreme k (x min, x max, y min, ...) of the solution, in the LP frame, or an error.
double extremeOf(const LpSolution& solution, int k, double far_limit) {
  static constexpr const char* kAxisNames[] = {"x", "y", "z"};
  const char* axis_name = kAxisNames[k / 2];
  const bool minimum = k % 2 == 0;
  const int return_code = solution.return_codes[k], status = solution.statuses[k];
  if (return_code == GLP_EITLIM || return_code == GLP_ETMLIM) {
    throw HullBoxError(HullBoxError::Reason::kUnbounded,
                       std::string("the bounding-box LP did not converge within ") +
                           std::to_string(kIterationLimit) + " simplex iterations or " +
                           std::to_string(kTimeLimit_ms) +
                           " ms (degenerate silhouette bounds?): " + kUnboundedHint);
  }
  if (return_code != 0) {
    throwUnbounded(axis_name, minimum,
                   "the simplex method failed with GLPK code " + std::to_string(return_code));
  }
  if (status == GLP_NOFEAS) throw HullBoxError(HullBoxError::Reason::kEmpty, kEmptyHint);
  if (status == GLP_UNBND) throwUnbounded(axis_name, minimum, "the linear program is unbounded");
  if (status != GLP_OPT) {
    throwUnbounded(axis_name, minimum, "no optimum, GLPK status " + std::to_string(status));
  }
  const double value = solution.optima[k];
  if (!(std::abs(value) <= far_limit)) {
    throwUnbounded(axis_name, minimum,
                   "its optimum lies a million times farther out than the cameras");
  }
  return value;
}

}  // namespace

bool Box3d::contains(const Eigen::Vector3d& X_W, double tolerance_m) const {
  return (X_W.array() >= min_W.array() - tolerance_m).all() &&
         (X_W.array() <= max_W.array() + tolerance_m).all();
}

std::vector<std::string> viewsSeeingBoxBehind(const Box3d& box,
                                              const std::vector<PinholeCamera>& cameras,
                                              const std::vector<std::string>& names) {
  const std::vector<std::string> given =
      names.size() == cameras.size() ? names : std::vector<std::string>{};
  std::vector<std::string> behind;
  for (size_t i = 0; i < cameras.size(); ++i) {
    if (!(cameras[i].depth(box.centre()) > 0.0)) behind.push_back(viewName(given, i));
  }
  return behind;
}

SilhouetteBounds silhouetteBounds(const cv::Mat& mask, bool border_bounds_object) {
  if (mask.empty()) throw std::invalid_argument("silhouetteBounds: the mask is empty");
  if (mask.type() != CV_8UC1) throw std::invalid_argument("silhouetteBounds: mask is not CV_8UC1");
  // cv::boundingRect of a CV_8UC1 image: the rectangle of its non-zero pixels.
  return boundsOfInside(cv::boundingRect(mask), mask.size(), border_bounds_object);
}

SilhouetteBounds boundsOfInside(const cv::Rect& inside, cv::Size image_size,
                                bool border_bounds_object) {
  SilhouetteBounds bounds;
  if (inside.empty()) return bounds;
  bounds.empty = false;
  bounds.u_min_px = inside.x - 0.5;
  bounds.u_max_px = inside.x + inside.width - 0.5;
  bounds.v_min_px = inside.y - 0.5;
  bounds.v_max_px = inside.y + inside.height - 0.5;
  bounds.has_u_min = border_bounds_object || inside.x > 0;
  bounds.has_u_max = border_bounds_object || inside.x + inside.width < image_size.width;
  bounds.has_v_min = border_bounds_object || inside.y > 0;
  bounds.has_v_max = border_bounds_object || inside.y + inside.height < image_size.height;
  return bounds;
}

namespace {

/// For an empty box: the views that see where the optical axes meet behind them, if any.
std::string behindNote(const std::vector<PinholeCamera>& cameras,
                       const std::vector<std::string>& names) {
  const CommonPoint scene = opticalAxesMeetingPoint(cameras);
  if (!scene.well_defined || scene.in_front_of_all) return "";
  std::string list;
  for (size_t i = 0; i < cameras.size(); ++i) {
    if (cameras[i].depth(scene.point_W) > 0.0) continue;
    list += (list.empty() ? "'" : ", '") + viewName(names, i) + "'";
  }
  return "; the point where the optical axes meet is behind " + list +
         " (the sign or handedness of their projection?)";
}

}  // namespace

Box3d hullBoundingBox(const std::vector<PinholeCamera>& cameras,
                      const std::vector<SilhouetteBounds>& bounds,
                      const std::vector<std::string>& names) {
  checkViews(cameras, bounds, names);
  std::vector<HalfSpace> half_spaces;
  for (size_t i = 0; i < cameras.size(); ++i) {
    if (bounds[i].boundedSides() > 0) appendViewHalfSpaces(cameras[i], bounds[i], &half_spaces);
  }
  const LpFrame frame = frameOfCameras(cameras);
  for (HalfSpace& half_space : half_spaces) half_space = toFrame(half_space, frame);
  for (const HalfSpace& half_space : half_spaces) {
    if (!half_space.coefficients.allFinite() || !std::isfinite(half_space.lower_bound)) {
      throw HullBoxError(HullBoxError::Reason::kUnbounded,
                         "a view's cone gives a degenerate LP row (a camera with a zero or "
                         "non-finite projection row?): check the calibration");
    }
  }
  LpSolution solution;
  solveBoxLp(half_spaces.data(), static_cast<int>(half_spaces.size()), &solution);
  if (solution.aborted) {
    throw HullBoxError(HullBoxError::Reason::kUnbounded,
                       "GLPK failed on the bounding-box LP (numerically degenerate cones): " +
                           std::string(kUnboundedHint));
  }
  const double far_limit = farCoordinateLimit(cameras, frame);
  Box3d box;
  try {
    for (int axis = 0; axis < 3; ++axis) {
      box.min_W(axis) = frame.origin(axis) + frame.scale * extremeOf(solution, 2 * axis, far_limit);
      box.max_W(axis) =
          frame.origin(axis) + frame.scale * extremeOf(solution, 2 * axis + 1, far_limit);
    }
  } catch (const HullBoxError& e) {
    if (e.reason() != HullBoxError::Reason::kEmpty) throw;
    throw HullBoxError(e.reason(), e.what() + behindNote(cameras, names));
  }
  // The LP frame's optimum, scaled back, can overflow where the cameras lie near 1e300.
  if (!box.min_W.allFinite() || !box.max_W.allFinite()) {
    throw HullBoxError(HullBoxError::Reason::kUnbounded,
                       "the bounding box lies beyond double precision (cameras near 1e300?): "
                       "check the calibration");
  }
  // Cones that meet only at a common apex, along a line or in a plane bound no volume.
  if (!(box.size().minCoeff() > kMinRelativeExtent * frame.scale)) {
    throw HullBoxError(HullBoxError::Reason::kEmpty,
                       "the viewing cones meet in a point, a line or a plane, not in a volume: " +
                           std::string(kEmptyHint));
  }
  return box;
}

}  // namespace sift_hull
