// Silhouettes from the photographs of a calibrated set (sift_hull/hull/view_silhouettes.h).

#include "sift_hull/hull/view_silhouettes.h"

#include <algorithm>
#include <array>
#include <chrono>
#include <cmath>
#include <limits>
#include <opencv2/core/utility.hpp>
#include <opencv2/imgproc.hpp>
#include <sstream>
#include <stdexcept>

#include "hull/plane_consistency.h"
#include "hull/silhouette_parts.h"
#include "hull/view_prior.h"

namespace sift_hull {
namespace {

using silhouette_parts::disc;
using silhouette_parts::largeComponents;
using view_prior::CoarseHull;
using view_prior::PixelScale;

/// The frusta's half-spaces in world coordinates, each (normal, offset) with unit normal: inside
/// when normal . X + offset >= 0. Four image sides (ideal pixels) and the image plane per view.
std::vector<Eigen::Vector4d> frustumPlanes(const std::vector<PinholeCamera>& cameras,
                                           cv::Size size) {
  std::vector<Eigen::Vector4d> planes;
  for (const PinholeCamera& camera : cameras) {
    const Eigen::Matrix3d& K = camera.K();
    const double u_min = -0.5, u_max = size.width - 0.5;
    const double v_min = -0.5, v_max = size.height - 0.5;
    // In camera coordinates: K.row(0) . Xc >= u_min z and so on, with z > 0.
    const Eigen::Vector3d sides[5] = {K.row(0).transpose() - u_min * Eigen::Vector3d::UnitZ(),
                                      u_max * Eigen::Vector3d::UnitZ() - K.row(0).transpose(),
                                      K.row(1).transpose() - v_min * Eigen::Vector3d::UnitZ(),
                                      v_max * Eigen::Vector3d::UnitZ() - K.row(1).transpose(),
                                      Eigen::Vector3d::UnitZ()};
    for (const Eigen::Vector3d& a : sides) {
      const Eigen::Vector3d normal = camera.R().transpose() * a;
      const double length = normal.norm();
      if (!(length > 0.0)) continue;
      planes.emplace_back(normal.x() / length, normal.y() / length, normal.z() / length,
                          a.dot(camera.t()) / length);
    }
  }
  return planes;
}

/// Views each view's pixels are compared with through the support plane.
constexpr int kPlaneNeighbours = 4;

/// The band along the image border, `fraction` of the smaller side, at least 2 pixels.
cv::Mat borderBand(cv::Size size, double fraction) {
  const int width =
      std::max(2, static_cast<int>(std::lround(fraction * std::min(size.width, size.height))));
  cv::Mat band(size, CV_8UC1, cv::Scalar(255));
  if (size.width > 2 * width && size.height > 2 * width) {
    band(cv::Rect(width, width, size.width - 2 * width, size.height - 2 * width)).setTo(0);
  }
  return band;
}

/// The colours the cuts compare: CIE Lab with the lightness scaled by kLightnessWeight, so that a
/// shadow (the floor's colour, darker) lies nearer the lit floor than another colour does.
constexpr double kLightnessWeight = 0.35;
cv::Mat cutColours(const cv::Mat& bgr) {
  const cv::Mat lab = silhouette_parts::labOf(bgr);
  cv::Mat out(bgr.size(), CV_8UC3);
  for (int y = 0; y < lab.rows; ++y) {
    const cv::Vec3f* in = lab.ptr<cv::Vec3f>(y);
    cv::Vec3b* o = out.ptr<cv::Vec3b>(y);
    for (int x = 0; x < lab.cols; ++x) {
      o[x] = cv::Vec3b(cv::saturate_cast<uint8_t>(2.55 * kLightnessWeight * in[x][0]),
                       cv::saturate_cast<uint8_t>(in[x][1] + 128.0),
                       cv::saturate_cast<uint8_t>(in[x][2] + 128.0));
    }
  }
  return out;
}

/// GrabCut from a labelling; the foreground (certain or probable) as 255.
cv::Mat cut(const cv::Mat& bgr, cv::Mat labels, int iterations) {
  const cv::Mat image = cutColours(bgr);
  const bool has_foreground = cv::countNonZero((labels == cv::GC_FGD) | (labels == cv::GC_PR_FGD));
  const bool has_background = cv::countNonZero((labels == cv::GC_BGD) | (labels == cv::GC_PR_BGD));
  if (!has_foreground || !has_background) return (labels & 1) * 255;
  cv::Mat background_model, foreground_model;
  // GrabCut's k-means draws from the thread's generator: seeded, the same masks every run.
  cv::theRNG().state = 0x12345678;
  cv::grabCut(image, labels, cv::Rect(), background_model, foreground_model, iterations,
              cv::GC_INIT_WITH_MASK);
  return (labels & 1) * 255;  // GC_FGD = 1, GC_PR_FGD = 3
}

/// A closing by a disc of `radius` (what a dark rim or fold split), and the holes under 1 % of the
/// mask's area filled (specks the cut left; a real opening through the object is larger).
cv::Mat closeAndFill(const cv::Mat& mask, int radius) {
  cv::Mat closed;
  if (radius > 0) {
    cv::morphologyEx(mask, closed, cv::MORPH_CLOSE, disc(radius), cv::Point(-1, -1), 1,
                     cv::BORDER_REPLICATE);
  } else {
    closed = mask.clone();
  }
  cv::Mat holes = closed == 0, labels, stats, centroids;
  const int count = cv::connectedComponentsWithStats(holes, labels, stats, centroids, 4, CV_32S);
  const double area = cv::countNonZero(closed);
  for (int i = 1; i < count; ++i) {
    const int x = stats.at<int>(i, cv::CC_STAT_LEFT), y = stats.at<int>(i, cv::CC_STAT_TOP);
    const int w = stats.at<int>(i, cv::CC_STAT_WIDTH), h = stats.at<int>(i, cv::CC_STAT_HEIGHT);
    const bool touches_border = x == 0 || y == 0 || x + w == closed.cols || y + h == closed.rows;
    if (!touches_border && stats.at<int>(i, cv::CC_STAT_AREA) < 0.01 * area) {
      closed.setTo(255, labels == i);
    }
  }
  return closed;
}

double maskIou(const cv::Mat& a, const cv::Mat& b) {
  const double both = cv::countNonZero(a & b), either = cv::countNonZero(a | b);
  return either > 0.0 ? both / either : 1.0;
}

/// The box of the views' frusta (hullBoundingBox with whole images).
Box3d frustaBox(const std::vector<PinholeCamera>& cameras, const std::vector<std::string>& names,
                cv::Size full_size) {
  const std::vector<SilhouetteBounds> whole(
      cameras.size(), boundsOfInside(cv::Rect(cv::Point(0, 0), full_size), full_size, true));
  try {
    return hullBoundingBox(cameras, whole, names);
  } catch (const HullBoxError& e) {
    throw std::runtime_error(std::string("the views' frusta have no bounded common part (") +
                             e.what() + "): give masks with --silhouettes");
  }
}

/// A coarse hull of `masks` inside `box`, its largest part, carved again on a grid over that
/// part's box (finer cells where the object is).
CoarseHull carveTight(const std::vector<cv::Mat>& masks, const std::vector<PinholeCamera>& cameras,
                      const PixelScale& scale, const Box3d& box, int tolerated) {
  CoarseHull hull = view_prior::carve(masks, cameras, scale, box, kCoarseCells, tolerated);
  view_prior::keepLargestPart(&hull);
  if (!hull.centres_W.empty()) {
    hull = view_prior::carve(masks, cameras, scale, view_prior::boxOf(hull, 2.0), kCoarseCells,
                             tolerated);
    view_prior::keepLargestPart(&hull);
  }
  return hull;
}

/// What silhouetteAgreement resolves: outlines a pixel or two apart at the working size (half a
/// coarse cell) change it by one to two hundredths.
constexpr double kAgreementResolution = 0.01;

}  // namespace

void chooseBackgroundWhereItAgrees(ViewSilhouettes* found, std::vector<cv::Mat> plain,
                                   const std::vector<std::string>& names,
                                   const std::vector<PinholeCamera>& cameras,
                                   const SilhouetteConfig& recipe) {
  for (size_t i = 0; i < plain.size(); ++i) {
    if (plain[i].empty()) {
      found->background_reason =
          names[i] + ": its border is textured (the background method would need GrabCut)";
      return;
    }
  }
  found->background_agreement = silhouetteAgreement(plain, cameras, names, recipe.segment_side_px);
  if (found->background_agreement >= found->agreement - kAgreementResolution) {
    found->method = "background";
    found->masks = std::move(plain);
    found->warnings.clear();  // they named the views method's masks
  }
}

double silhouetteAgreement(const std::vector<cv::Mat>& masks,
                           const std::vector<PinholeCamera>& cameras,
                           const std::vector<std::string>& names, int segment_side_px) {
  const size_t n = masks.size();
  if (n < 2 || cameras.size() != n || names.size() != n) {
    throw std::invalid_argument("silhouetteAgreement: two masks or more, each with its camera");
  }
  const cv::Size full_size = masks.front().size();
  const cv::Size size = workingSize(full_size, segment_side_px);
  const PixelScale scale{static_cast<double>(size.width) / full_size.width,
                         static_cast<double>(size.height) / full_size.height};
  std::vector<cv::Mat> small(n);
  for (size_t v = 0; v < n; ++v) {
    if (masks[v].size() != full_size || masks[v].type() != CV_8UC1) {
      throw std::invalid_argument("silhouetteAgreement: " + names[v] +
                                  "'s mask is not CV_8UC1 of the first's size");
    }
    cv::resize(masks[v], small[v], size, 0, 0, cv::INTER_AREA);
    small[v] = small[v] >= 128;
  }
  const CoarseHull hull =
      carveTight(small, cameras, scale, frustaBox(cameras, names, full_size), 0);
  if (hull.centres_W.empty()) return 0.0;
  std::vector<double> iou(n);
  cv::parallel_for_(cv::Range(0, static_cast<int>(n)), [&](const cv::Range& range) {
    for (int v = range.start; v < range.end; ++v) {
      iou[v] = maskIou(small[v], view_prior::project(hull, cameras[v], scale, size));
    }
  });
  double sum = 0.0;
  for (const double value : iou) sum += value;
  return sum / static_cast<double>(n);
}

cv::Size workingSize(cv::Size full_size, int segment_side_px) {
  const int longest = std::max(full_size.width, full_size.height);
  if (longest <= segment_side_px) return full_size;
  const double s = static_cast<double>(segment_side_px) / longest;
  return {std::max(1, static_cast<int>(std::lround(full_size.width * s))),
          std::max(1, static_cast<int>(std::lround(full_size.height * s)))};
}

std::optional<std::pair<Eigen::Vector3d, double>> largestBallInFrusta(
    const std::vector<PinholeCamera>& cameras, cv::Size full_size, const Box3d& box) {
  const std::vector<Eigen::Vector4d> planes = frustumPlanes(cameras, full_size);
  const auto clearance = [&](const Eigen::Vector3d& X) {
    double d = std::numeric_limits<double>::infinity();
    for (const Eigen::Vector4d& p : planes) d = std::min(d, p.head<3>().dot(X) + p.w());
    for (int a = 0; a < 3; ++a) d = std::min({d, X[a] - box.min_W[a], box.max_W[a] - X[a]});
    return d;
  };
  // A grid of 24 steps per side, then two finer grids around the best point.
  Eigen::Vector3d best = box.centre(), step = box.size() / 24.0;
  double best_clearance = clearance(best);
  Eigen::Vector3d low = box.min_W + 0.5 * step;
  int steps = 24;
  for (int round = 0; round < 3; ++round) {
    for (int i = 0; i < steps; ++i) {
      for (int j = 0; j < steps; ++j) {
        for (int k = 0; k < steps; ++k) {
          const Eigen::Vector3d X = low + Eigen::Vector3d(i * step.x(), j * step.y(), k * step.z());
          const double c = clearance(X);
          if (c > best_clearance) best_clearance = c, best = X;
        }
      }
    }
    low = best - 2.0 * step;
    step /= 5.0;
    steps = 21;
  }
  if (!(best_clearance > 0.0)) return std::nullopt;
  return std::make_pair(best, best_clearance);
}

ViewSilhouettes silhouettesFromViews(const std::vector<cv::Mat>& images,
                                     const std::vector<PinholeCamera>& cameras,
                                     const std::vector<std::string>& names, cv::Size full_size,
                                     const SilhouetteConfig& config) {
  const auto start = std::chrono::steady_clock::now();
  const size_t n = images.size();
  if (n < 2 || cameras.size() != n || names.size() != n) {
    throw std::runtime_error("the views method needs two views or more, each with its camera");
  }
  const cv::Size size = images.front().size();
  PixelScale scale{static_cast<double>(size.width) / full_size.width,
                   static_cast<double>(size.height) / full_size.height};
  ViewSilhouettes result;
  // 1. The frusta's box and the largest ball inside them.
  const Box3d frusta = frustaBox(cameras, names, full_size);
  const auto ball = largestBallInFrusta(cameras, full_size, frusta);
  if (!ball) throw std::runtime_error("no point lies inside every view's frustum");
  result.ball_centre_W = ball->first;
  result.ball_radius = ball->second;

  // 2. Each view cut at half the working size, the ball's projection as probable object.
  const cv::Size half((size.width + 1) / 2, (size.height + 1) / 2);
  const PixelScale half_scale{scale.sx * half.width / size.width,
                              scale.sy * half.height / size.height};
  result.priors.resize(n);
  std::vector<cv::Mat> first(n);
  cv::parallel_for_(cv::Range(0, static_cast<int>(n)), [&](const cv::Range& range) {
    for (int v = range.start; v < range.end; ++v) {
      cv::Mat prior = cv::Mat::zeros(size, CV_8UC1);
      const double depth = cameras[v].depth(ball->first);
      if (depth > ball->second) {
        const Eigen::Vector2d c = scale(cameras[v].project(ball->first));
        const double radius = std::abs(cameras[v].K()(0, 0)) * scale.sx * ball->second /
                              std::sqrt(depth * depth - ball->second * ball->second);
        cv::circle(
            prior,
            cv::Point(static_cast<int>(std::lround(c.x())), static_cast<int>(std::lround(c.y()))),
            static_cast<int>(std::lround(radius)), cv::Scalar(255), cv::FILLED);
      } else {
        prior.setTo(255);
      }
      result.priors[v] = prior;
      cv::Mat small, small_prior;
      cv::resize(images[v], small, half, 0, 0, cv::INTER_AREA);
      cv::resize(prior, small_prior, half, 0, 0, cv::INTER_NEAREST);
      cv::Mat labels(half, CV_8UC1, cv::Scalar(cv::GC_PR_BGD));
      labels.setTo(cv::GC_PR_FGD, small_prior);
      labels.setTo(cv::GC_BGD, borderBand(half, 0.03));
      first[v] = largeComponents(cut(small, labels, 3));
    }
  });

  // 3. A coarse hull from those masks, a tenth of the views' disagreement tolerated; its support
  // cut.
  const int tolerated = static_cast<int>(n / 10);
  CoarseHull hull = carveTight(first, cameras, half_scale, frusta, tolerated);
  if (hull.centres_W.empty()) {
    throw std::runtime_error(
        "the views' segmentations share no object: nothing is inside all but " +
        std::to_string(tolerated) + " of the masks; give masks with --silhouettes");
  }
  result.up_W = view_prior::meanUp(cameras);
  // The plane the object stands on, if the views see one around it: swept over the lower half of
  // the coarse hull's height (which reaches below the floor: cameras above it cannot carve there).
  double bottom = std::numeric_limits<double>::infinity(), top = -bottom;
  for (const Eigen::Vector3d& c : hull.centres_W) {
    bottom = std::min(bottom, result.up_W.dot(c));
    top = std::max(top, result.up_W.dot(c));
  }
  const std::optional<double> plane =
      view_prior::supportHeight(images, first, cameras, scale, result.up_W, bottom,
                                0.5 * (bottom + top), hull.cell, &result.support_plane_share);
  result.support_plane_height = plane;
  result.support_fraction = view_prior::cutSupport(result.up_W, &hull, &result.support_height);

  // 4. The hull's projection as the prior of a second cut at the working size; the mask is that
  // cut inside the projection, grown by a margin.
  const int margin =
      std::max(3, static_cast<int>(std::lround(0.015 * std::max(size.width, size.height))));
  result.hull_projections.resize(n);
  result.masks.resize(n);
  std::vector<double> agreement(n, 1.0);
  std::vector<cv::Mat> greys;  // what the support plane is judged on, each view's made once
  if (plane) {
    for (const cv::Mat& image : images) greys.push_back(view_prior::planeGrey(image));
  }
  cv::parallel_for_(cv::Range(0, static_cast<int>(n)), [&](const cv::Range& range) {
    for (int v = range.start; v < range.end; ++v) {
      const cv::Mat projection = view_prior::project(hull, cameras[v], scale, size);
      result.hull_projections[v] = projection;
      cv::Mat grown, earlier;
      cv::dilate(projection, grown, disc(margin));
      cv::resize(first[v], earlier, size, 0, 0, cv::INTER_LINEAR);
      earlier = earlier >= 128;
      cv::Mat labels(size, CV_8UC1, cv::Scalar(cv::GC_BGD));
      labels.setTo(cv::GC_PR_BGD, grown);
      labels.setTo(cv::GC_PR_FGD, grown & earlier & projection);
      // Deep inside the hull's projection, what the first cut took is the object for certain.
      cv::Mat core;
      cv::erode(projection, core, disc(margin));
      labels.setTo(cv::GC_FGD, core & earlier);
      labels.setTo(cv::GC_BGD, borderBand(size, 0.03) & ~projection);
      // What lies on the support plane (floor, turntable, the object's shadow on them) is not
      // the object, whatever its colour.
      if (plane) {
        labels.setTo(cv::GC_BGD,
                     view_prior::onPlane(greys, cameras, scale, static_cast<size_t>(v), result.up_W,
                                         *plane, hull.cell, kPlaneNeighbours));
      }
      const cv::Mat mask = largeComponents(cut(images[v], labels, 2) & grown);
      agreement[v] = maskIou(mask, projection);
      cv::Mat full;
      cv::resize(mask, full, full_size, 0, 0, cv::INTER_LINEAR);
      result.masks[v] = closeAndFill(full >= 128, config.erode_px);
    }
  });
  result.agreement = silhouetteAgreement(result.masks, cameras, names, config.segment_side_px);
  for (size_t v = 0; v < n; ++v) {
    if (agreement[v] < 0.8) {
      std::ostringstream text;
      text << names[v] << ": its silhouette and the other views' hull disagree (IoU "
           << agreement[v] << "); look at its mask (--out-silhouettes) or leave the view out";
      result.warnings.push_back(text.str());
    }
  }
  result.time_ms =
      std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count();
  return result;
}

}  // namespace sift_hull
