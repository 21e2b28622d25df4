#pragma once

#include <memory>
#include <string>
#include <vector>

#include "sift_hull/features/matching.h"
#include "sift_hull/filters/epipolar.h"
#include "sift_hull/filters/filter_result.h"
#include "sift_hull/filters/gms.h"
#include "sift_hull/filters/gsc.h"
#include "sift_hull/filters/guided.h"
#include "sift_hull/filters/local_consistency.h"
#include "sift_hull/filters/ratio.h"
#include "sift_hull/filters/robust_fit.h"
#include "sift_hull/filters/vote_ransac.h"
#include "sift_hull/settings.h"

namespace sift_hull {

/// Every filter's configuration, as a node or the CLI holds them. Each setting is named as its
/// field in ROS parameters, dynamic_reconfigure, JSON and (with - for _) command-line flags
/// (`max_histogram_distance`, `--grid-cells`), with one exception: RobustFitConfig is held twice,
/// so its fields carry the member's name as a prefix (`ransac_max_epipolar_px`,
/// `magsac_confidence`, `--magsac-max-epipolar-px`).
struct FilterConfigs {
  EpipolarConfig epipolar;
  GscConfig gsc;
  RobustFitConfig ransac;
  RobustFitConfig magsac;
  GmsConfig gms;
  LscConfig lsc;
  LocalGscConfig local_gsc;
  GuidedConfig guided;
  VoteRansacConfig vote_ransac;
};
/// Its settings: names, units, ranges, help (sift_hull/settings.h).
template <>
const SettingTable<FilterConfigs>& settingsOf<FilterConfigs>();

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

/// The package's filters: ratio, epipolar, gsc, ransac, magsac, gms, lsc, local_gsc, guided,
/// vote_ransac, best. `best` is the combination measured best (docs/EVALUATION.md), the CLI's and
/// the node's default: today `vote_ransac`. makeFilter also knows `colmap`, COLMAP's own
/// verification run by its program when installed (colmap_verification.h), a peer to compare
/// with, which is not in this list.
const std::vector<std::string>& filterNames();

/// The filter the CLI (`match`, `hull --refine-with-matches`) and the matcher node run unless
/// told otherwise.
inline constexpr const char* kDefaultFilter = "best";

/// A filter by name; "a+b" composes filters, keeping what all keep (score: how many rejected the
/// match). Throws std::invalid_argument for an unknown name.
std::unique_ptr<MatchFilter> makeFilter(const std::string& spec, const FilterConfigs& configs);

}  // namespace sift_hull
