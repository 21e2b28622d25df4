#pragma once

#include <array>
#include <memory>
#include <string>
#include <vector>

#include "sift_hull/matching.h"

namespace sift_hull {

/// What a filter decides for each putative match, in the order of PutativeMatches::matches.
/// A match with a non-finite coordinate is never kept and has a NaN score, whatever the filter.
struct FilterResult {
  std::vector<uint8_t> keep;  ///< 1 to keep the match
  std::vector<double> score;  ///< the filter's own measure; see each config for its meaning

  size_t keptCount() const;
  /// A result keeping none of `matches` matches, every score NaN: where each filter starts.
  static FilterResult keepingNone(size_t matches);
};

/// Keeps a match when each point lies within max_epipolar_px of the other's epipolar line under
/// the calibrated F, checked in both images ("reverse validation"). Score: the larger of the two
/// point-to-line distances, in pixels. Needs PutativeMatches::F_right_left.
struct EpipolarConfig {
  double max_epipolar_px = 2.0;
};

/// The global scale-invariant constraint. Score: the Euclidean distance between the match's
/// normalised left and right polar-angle histograms (0 to sqrt(2)).
struct GscConfig {
  double max_histogram_distance = 0.2;
  int threads = 0;  ///< 0 uses all hardware threads
};

/// cv::findFundamentalMat with FM_RANSAC ("ransac") or USAC_MAGSAC ("magsac"). Score: the larger
/// of the two point-to-epipolar-line distances under the estimated F, in pixels (NaN when no F
/// was found). Fewer than 8 valid matches: none kept.
struct RobustFitConfig {
  double max_epipolar_px = 1.0;
  double confidence = 0.99;
  int max_iterations = 1000;
};

/// Grid-based Motion Statistics (Bian et al., CVPR 2017). Score: the support of the match's cell
/// pair divided by the cell's threshold, so a match is kept when its score exceeds 1.
struct GmsConfig {
  int grid_cells = 20;            ///< cells per image side (the paper's G = 20 x 20)
  double threshold_factor = 6.0;  ///< alpha in tau = alpha * sqrt(n)
  bool with_rotation = false;     ///< try the 8 rotations of the 3x3 neighbourhood
  bool with_scale = false;        ///< try 5 relative grid scales of the right image
};

/// Every filter's configuration, as a node or the CLI holds them.
struct FilterConfigs {
  EpipolarConfig epipolar;
  GscConfig gsc;
  RobustFitConfig ransac;
  RobustFitConfig magsac;
  GmsConfig gms;
};

/// Throws std::invalid_argument naming the first bad field.
void validate(const FilterConfigs& configs);

/// One way of telling correct putative matches from mismatches.
class MatchFilter {
 public:
  virtual ~MatchFilter() = default;
  virtual std::string name() const = 0;
  /// Throws std::invalid_argument when the input lacks what the filter needs (calibration).
  virtual FilterResult apply(const PutativeMatches& input) const = 0;
};

/// The names makeFilter knows: ratio, epipolar, gsc, ransac, magsac, gms.
const std::vector<std::string>& filterNames();

/// A filter by name; "a+b" composes filters, keeping what all keep (score: how many rejected the
/// match). Throws std::invalid_argument for an unknown name.
std::unique_ptr<MatchFilter> makeFilter(const std::string& spec, const FilterConfigs& configs);

FilterResult filterRatio(const PutativeMatches& input);  ///< keeps all; score: descriptor distance
FilterResult filterEpipolar(const PutativeMatches& input, const EpipolarConfig& config);
FilterResult filterGsc(const PutativeMatches& input, const GscConfig& config);
FilterResult filterRansac(const PutativeMatches& input, const RobustFitConfig& config);
FilterResult filterMagsac(const PutativeMatches& input, const RobustFitConfig& config);
FilterResult filterGms(const PutativeMatches& input, const GmsConfig& config);

/// Number of polar-angle sectors of the GSC histogram (45 degrees each).
inline constexpr int kGscSectors = 8;
using GscHistogram = std::array<double, kGscSectors>;

/// The normalised left and right GSC histograms of one match, for display and checks.
struct GscHistograms {
  GscHistogram left{};
  GscHistogram right{};
  double distance() const;
};
GscHistograms gscHistograms(const PutativeMatches& input, size_t match);

}  // namespace sift_hull
