#include "sift_hull/filters/filter.h"

#include <cmath>
#include <sstream>
#include <stdexcept>

#include "sift_hull/filters/colmap_verification.h"
#include "sift_hull/limits.h"

namespace sift_hull {
namespace {

/// A filter made of a function of the input and a config.
template <typename Config>
class FunctionFilter : public MatchFilter {
 public:
  using Function = FilterResult (*)(const PutativeMatches&, const Config&);
  FunctionFilter(std::string name, Function function, Config config)
      : name_(std::move(name)), function_(function), config_(config) {}
  std::string name() const override { return name_; }
  FilterResult apply(const PutativeMatches& input) const override {
    return function_(input, config_);
  }

 private:
  std::string name_;
  Function function_;
  Config config_;
};

/// Keeps what all its parts keep; score: how many parts rejected the match.
class CompositeFilter : public MatchFilter {
 public:
  explicit CompositeFilter(std::vector<std::unique_ptr<MatchFilter>> parts)
      : parts_(std::move(parts)) {}
  std::string name() const override;
  FilterResult apply(const PutativeMatches& input) const override;

 private:
  std::vector<std::unique_ptr<MatchFilter>> parts_;
};

std::string CompositeFilter::name() const {
  std::string joined;
  for (const auto& part : parts_) joined += (joined.empty() ? "" : "+") + part->name();
  return joined;
}

FilterResult CompositeFilter::apply(const PutativeMatches& input) const {
  FilterResult result{std::vector<uint8_t>(input.matches.size(), 1),
                      std::vector<double>(input.matches.size(), 0.0)};
  for (const auto& part : parts_) {
    const FilterResult partial = part->apply(input);
    for (size_t m = 0; m < input.matches.size(); ++m) {
      result.keep[m] = result.keep[m] && partial.keep[m];
      result.score[m] += partial.keep[m] ? 0.0 : 1.0;
    }
  }
  for (size_t m = 0; m < input.matches.size(); ++m) {
    if (!input.hasFinitePositions(m)) result.score[m] = NAN;
  }
  return result;
}

FilterResult ratioWithConfig(const PutativeMatches& input, const int&) {
  return filterRatio(input);
}

std::unique_ptr<MatchFilter> makeSingleFilter(const std::string& name,
                                              const FilterConfigs& configs) {
  if (name == "ratio") return std::make_unique<FunctionFilter<int>>(name, ratioWithConfig, 0);
  if (name == "epipolar") {
    return std::make_unique<FunctionFilter<EpipolarConfig>>(name, filterEpipolar, configs.epipolar);
  }
  if (name == "gsc") {
    return std::make_unique<FunctionFilter<GscConfig>>(name, filterGsc, configs.gsc);
  }
  if (name == "ransac") {
    return std::make_unique<FunctionFilter<RobustFitConfig>>(name, filterRansac, configs.ransac);
  }
  if (name == "magsac") {
    return std::make_unique<FunctionFilter<RobustFitConfig>>(name, filterMagsac, configs.magsac);
  }
  if (name == "gms") {
    return std::make_unique<FunctionFilter<GmsConfig>>(name, filterGms, configs.gms);
  }
  if (name == "lsc")
    return std::make_unique<FunctionFilter<LscConfig>>(name, filterLsc, configs.lsc);
  if (name == "local_gsc") {
    return std::make_unique<FunctionFilter<LocalGscConfig>>(name, filterLocalGsc,
                                                            configs.local_gsc);
  }
  if (name == "guided") {
    return std::make_unique<FunctionFilter<GuidedFilterConfig>>(
        name, filterGuided, GuidedFilterConfig{configs.guided, configs.lsc, configs.magsac});
  }
  if (name == "vote_ransac" || name == "best") {
    return std::make_unique<FunctionFilter<VoteRansacFilterConfig>>(
        name, filterVoteRansac,
        VoteRansacFilterConfig{configs.vote_ransac, configs.guided, configs.magsac});
  }
  if (name == "colmap") {
    return std::make_unique<FunctionFilter<ColmapConfig>>(
        name, filterColmap, ColmapConfig{"colmap", configs.magsac.seed, 1});
  }
  std::ostringstream known;
  for (const std::string& each : filterNames()) known << " " << each;
  known << " colmap";
  throw std::invalid_argument("unknown filter '" + name + "' (known:" + known.str() + ")");
}

}  // namespace

FilterResult FilterResult::keepingNone(size_t matches) {
  return {std::vector<uint8_t>(matches, 0), std::vector<double>(matches, NAN)};
}

size_t FilterResult::keptCount() const {
  size_t count = 0;
  for (uint8_t flag : keep) count += flag ? 1 : 0;
  return count;
}

const std::vector<std::string>& filterNames() {
  static const std::vector<std::string> names = {"ratio",  "epipolar",    "gsc", "ransac",
                                                 "magsac", "gms",         "lsc", "local_gsc",
                                                 "guided", "vote_ransac", "best"};
  return names;
}

std::unique_ptr<MatchFilter> makeFilter(const std::string& spec, const FilterConfigs& configs) {
  validate(configs);
  std::vector<std::unique_ptr<MatchFilter>> parts;
  size_t start = 0;
  for (;;) {
    const size_t plus = spec.find('+', start);
    const std::string name = spec.substr(start, plus == std::string::npos ? plus : plus - start);
    if (name.empty()) throw std::invalid_argument("empty filter name in '" + spec + "'");
    parts.push_back(makeSingleFilter(name, configs));
    if (plus == std::string::npos) break;
    start = plus + 1;
  }
  if (parts.size() == 1) return std::move(parts.front());
  return std::make_unique<CompositeFilter>(std::move(parts));
}

}  // namespace sift_hull
