#include "sift_hull/bounding_box.h"

#include <glpk.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <opencv2/imgproc.hpp>
#include <string>
#include <vector>

namespace sift_hull {
namespace {

// A box coordinate this many times farther out than the farthest camera centre is not a bound:
// near-parallel cones give finite but meaningless optima of that size.
constexpr double kFarCoordinateFactor = 1e6;

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
    if (!boundsAreFinite(bounds[i])) {
      throw std::invalid_argument("the silhouette bounds of " + viewName(names, i) +
                                  " are not finite");
    }
    if (bounds[i].boundedSides() > 0) ++bounding_views;
  }
  if (bounding_views < 2) {
    throw HullBoxError(HullBoxError::Reason::kTooFewViews,
                       std::to_string(bounding_views) +
                           " view(s) with a bounded silhouette side; at least two are needed");
  }
}

/// Owns a glp_prob.
class GlpkProblem {
 public:
  GlpkProblem() : problem_(glp_create_prob()) {}
  ~GlpkProblem() { glp_delete_prob(problem_); }
  GlpkProblem(const GlpkProblem&) = delete;
  GlpkProblem& operator=(const GlpkProblem&) = delete;
  glp_prob* get() const { return problem_; }

 private:
  glp_prob* problem_;
};

/// Turns GLPK's terminal output off for its lifetime and then restores the previous state.
class GlpkTerminalSilencer {
 public:
  GlpkTerminalSilencer() : previous_state_(glp_term_out(GLP_OFF)) {}
  ~GlpkTerminalSilencer() { glp_term_out(previous_state_); }
  GlpkTerminalSilencer(const GlpkTerminalSilencer&) = delete;
  GlpkTerminalSilencer& operator=(const GlpkTerminalSilencer&) = delete;

 private:
  int previous_state_;
};

/// Columns 1..3 are the free variables x, y, z; one row per half-space.
void fillProblem(const std::vector<HalfSpace>& half_spaces, glp_prob* problem) {
  glp_add_cols(problem, 3);
  for (int column = 1; column <= 3; ++column) glp_set_col_bnds(problem, column, GLP_FR, 0.0, 0.0);
  glp_add_rows(problem, static_cast<int>(half_spaces.size()));
  const std::array<int, 4> columns = {0, 1, 2, 3};  // GLPK arrays start at index 1
  for (size_t i = 0; i < half_spaces.size(); ++i) {
    const int row = static_cast<int>(i) + 1;
    const Eigen::Vector3d& a = half_spaces[i].coefficients;
    const std::array<double, 4> values = {0.0, a.x(), a.y(), a.z()};
    glp_set_mat_row(problem, row, 3, columns.data(), values.data());
    glp_set_row_bnds(problem, row, GLP_LO, half_spaces[i].lower_bound, 0.0);
  }
}

double farCoordinateLimit(const std::vector<PinholeCamera>& cameras) {
  double farthest_centre = 1.0;
  for (const PinholeCamera& camera : cameras) {
    farthest_centre = std::max(farthest_centre, camera.centre().cwiseAbs().maxCoeff());
  }
  return kFarCoordinateFactor * farthest_centre;
}

[[noreturn]] void throwUnbounded(const char* axis_name, int direction, const std::string& detail) {
  const std::string side = direction == GLP_MIN ? "minimum" : "maximum";
  throw HullBoxError(HullBoxError::Reason::kUnbounded, "the bounding box has no finite " + side +
                                                           " " + axis_name + " (" + detail +
                                                           "): " + kUnboundedHint);
}

/// The minimum or maximum (direction GLP_MIN or GLP_MAX) of one coordinate (column 1..3).
double solveExtreme(glp_prob* problem, int column, int direction, double far_limit) {
  static constexpr const char* kAxisNames[] = {"x", "y", "z"};
  const char* axis_name = kAxisNames[column - 1];
  for (int j = 1; j <= 3; ++j) glp_set_obj_coef(problem, j, j == column ? 1.0 : 0.0);
  glp_set_obj_dir(problem, direction);
  glp_smcp parameters;
  glp_init_smcp(&parameters);
  parameters.msg_lev = GLP_MSG_OFF;
  parameters.presolve = GLP_OFF;
  const int return_code = glp_simplex(problem, &parameters);
  if (return_code != 0) {
    throwUnbounded(axis_name, direction,
                   "the simplex method failed with GLPK code " + std::to_string(return_code));
  }
  const int status = glp_get_status(problem);
  if (status == GLP_NOFEAS) throw HullBoxError(HullBoxError::Reason::kEmpty, kEmptyHint);
  if (status == GLP_UNBND) throwUnbounded(axis_name, direction, "the linear program is unbounded");
  if (status != GLP_OPT) {
    throwUnbounded(axis_name, direction, "no optimum, GLPK status " + std::to_string(status));
  }
  const double value = glp_get_col_prim(problem, column);
  if (!(std::abs(value) <= far_limit)) {
    throwUnbounded(axis_name, direction,
                   "its optimum " + std::to_string(value) +
                       " lies a million times farther out than the cameras");
  }
  return value;
}

}  // namespace

bool Box3d::contains(const Eigen::Vector3d& X_W, double tolerance_m) const {
  return (X_W.array() >= min_W.array() - tolerance_m).all() &&
         (X_W.array() <= max_W.array() + tolerance_m).all();
}

SilhouetteBounds silhouetteBounds(const cv::Mat& mask, bool border_bounds_object) {
  if (mask.empty()) throw std::invalid_argument("silhouetteBounds: the mask is empty");
  if (mask.type() != CV_8UC1) throw std::invalid_argument("silhouetteBounds: mask is not CV_8UC1");
  SilhouetteBounds bounds;
  const cv::Rect inside = cv::boundingRect(mask);  // of the non-zero pixels of a CV_8UC1 image
  if (inside.empty()) return bounds;
  bounds.empty = false;
  bounds.u_min_px = inside.x - 0.5;
  bounds.u_max_px = inside.x + inside.width - 0.5;
  bounds.v_min_px = inside.y - 0.5;
  bounds.v_max_px = inside.y + inside.height - 0.5;
  bounds.has_u_min = border_bounds_object || inside.x > 0;
  bounds.has_u_max = border_bounds_object || inside.x + inside.width < mask.cols;
  bounds.has_v_min = border_bounds_object || inside.y > 0;
  bounds.has_v_max = border_bounds_object || inside.y + inside.height < mask.rows;
  return bounds;
}

Box3d hullBoundingBox(const std::vector<PinholeCamera>& cameras,
                      const std::vector<SilhouetteBounds>& bounds,
                      const std::vector<std::string>& names) {
  checkViews(cameras, bounds, names);
  std::vector<HalfSpace> half_spaces;
  for (size_t i = 0; i < cameras.size(); ++i) {
    if (bounds[i].boundedSides() > 0) appendViewHalfSpaces(cameras[i], bounds[i], &half_spaces);
  }
  const GlpkTerminalSilencer silencer;
  const GlpkProblem problem;
  fillProblem(half_spaces, problem.get());
  const double far_limit = farCoordinateLimit(cameras);
  Box3d box;
  for (int axis = 0; axis < 3; ++axis) {
    box.min_W(axis) = solveExtreme(problem.get(), axis + 1, GLP_MIN, far_limit);
    box.max_W(axis) = solveExtreme(problem.get(), axis + 1, GLP_MAX, far_limit);
  }
  return box;
}

}  // namespace sift_hull
