// evaluate-filters: precision, recall and F1 of every filter on real pairs with ground truth
// (Teddy at three ratios, graf 1-2 to 1-5) and on synthetic pairs (a scene pair, two objects
// moving differently, a strong rotation and zoom). Randomised filters: means over seeds 0 to 4.

#include <algorithm>
#include <cmath>
#include <iomanip>
#include <map>
#include <sstream>

#include "args.h"
#include "bench_commands.h"
#include "bench_report.h"
#include "commands.h"
#include "match_eval.h"
#include "pair_data.h"
#include "sift_hull/features/labelled_matches.h"
#include "sift_hull/filters/colmap_verification.h"
#include "sift_hull/filters/filter.h"
#include "sift_hull/synthetic/scene.h"
#include "sift_hull/synthetic/warped_pairs.h"

namespace sift_hull {
namespace cli {
namespace {

/// Two neighbouring views (22.5 degrees apart) of the default synthetic scene, 640x480.
EvaluationPair scenePair(const MatchOptions& options) {
  const SceneConfig config;
  const RenderedView left = renderSceneView(config, 0), right = renderSceneView(config, 1);
  EvaluationPair pair;
  pair.name = "synthetic scene, views 0-1";
  PutativeMatches& input = pair.matches.putative;
  input = matchImages(left.image, right.image, options.sift, options.matching);
  calibratePair(&input, left.view.camera, right.view.camera);
  pair.matches.truth =
      judgeBySceneDepth(input, {left.view.camera, left.depth}, {right.view.camera, right.depth});
  return pair;
}

/// A pair made by warping one rendered view (warped_pairs.h), judged by its motions.
EvaluationPair warpedEvaluationPair(const std::string& name, const WarpedPair& warped,
                                    const MatchOptions& options) {
  EvaluationPair pair;
  pair.name = name;
  pair.matches.putative = matchImages(warped.left, warped.right, options.sift, options.matching);
  pair.matches.truth = judgeByMotions(pair.matches.putative, warped);
  return pair;
}

/// The filters whose answer depends on a random state.
bool randomised(const std::string& name) {
  return name == "ransac" || name == "magsac" || name == "guided" || name == "vote_ransac" ||
         name == "best" || name == "colmap";
}

constexpr int kSeeds = 5;

/// One filter on one pair: its run, or for a randomised filter the means over seeds 0..4 of the
/// scores, kept counts and times, with each seed's F1.
nlohmann::json filterJson(const std::string& name, FilterConfigs configs,
                          const LabelledMatches& matches) {
  if (!randomised(name)) {
    return filterRunJson(timedRun(*makeFilter(name, configs), matches.putative), &matches.truth);
  }
  nlohmann::json mean, f1s = nlohmann::json::array();
  for (int seed = 0; seed < kSeeds; ++seed) {
    configs.magsac.seed = configs.ransac.seed = seed;
    const nlohmann::json run =
        filterRunJson(timedRun(*makeFilter(name, configs), matches.putative), &matches.truth);
    f1s.push_back(run["f1"]);
    for (const char* key : {"kept", "time_ms", "precision", "recall", "f1", "mismatches_removed"}) {
      const double value = run[key].is_null() ? 0.0 : run[key].get<double>();
      mean[key] = (mean.contains(key) ? mean[key].get<double>() : 0.0) + value / kSeeds;
    }
  }
  mean["f1_per_seed"] = f1s;
  mean["seeds"] = kSeeds;
  return mean;
}

nlohmann::json evaluatePair(const EvaluationPair& pair, double ratio,
                            const std::vector<std::string>& filters, const FilterConfigs& configs) {
  const LabelledMatches& matches = pair.matches;
  nlohmann::json row = {{"pair", pair.name}, {"ratio", ratio}, {"putative", matches.truth.size()}};
  row["ground_truth"] = truthJson("", matches.truth);
  row["ground_truth"].erase("kind");
  row["filters"] = nlohmann::json::object();
  for (const std::string& name : filters) {
    if (name == "epipolar" && !matches.putative.F_right_left) continue;
    row["filters"][name] = filterJson(name, configs, matches);
  }
  return row;
}

std::string cell(const nlohmann::json& value) {
  if (value.is_null()) return "-";
  std::ostringstream out;
  out << std::fixed << std::setprecision(3) << value.get<double>();
  return out.str();
}

/// F1 over the pairs: a filter's mean (a pair where it keeps nothing counts 0), and what the
/// target of docs/EVALUATION.md on `best` against MAGSAC is judged on: the difference of their
/// mean F1s, and their smallest difference on one pair (which pair it is in `worst_pair`).
nlohmann::json summaryJson(const nlohmann::json& rows) {
  std::map<std::string, std::vector<double>> f1;
  double worst = INFINITY;
  std::string worst_pair;
  for (const auto& row : rows) {
    for (const auto& [name, run] : row["filters"].items()) {
      f1[name].push_back(run["f1"].is_null() ? 0.0 : run["f1"].get<double>());
    }
    const auto& filters = row["filters"];
    if (filters.contains("best") && filters.contains("magsac")) {
      const double difference = f1["best"].back() - f1["magsac"].back();
      if (difference < worst) worst = difference, worst_pair = row["pair"].get<std::string>();
    }
  }
  nlohmann::json summary = {{"mean_f1", nlohmann::json::object()}};
  for (const auto& [name, values] : f1) {
    double sum = 0.0;
    for (double v : values) sum += v;
    summary["mean_f1"][name] = {{"mean", sum / values.size()}, {"pairs", values.size()}};
  }
  // Each pair's strongest other filter (vote_ransac is best under its own name: not a peer).
  nlohmann::json peers = nlohmann::json::array();
  double worst_peer_gap = INFINITY;
  std::string worst_peer_pair;
  for (const auto& row : rows) {
    const auto& filters = row["filters"];
    if (!filters.contains("best")) continue;
    const auto f1Of = [](const nlohmann::json& run) {
      return run["f1"].is_null() ? 0.0 : run["f1"].get<double>();
    };
    std::string peer;
    double peer_f1 = -1.0;
    for (const auto& [name, run] : filters.items()) {
      if (name == "best" || name == "vote_ransac" || f1Of(run) <= peer_f1) continue;
      peer = name, peer_f1 = f1Of(run);
    }
    if (peer.empty()) continue;
    const double gap = f1Of(filters["best"]) - peer_f1;
    peers.push_back({{"pair", row["pair"]},
                     {"best_f1", f1Of(filters["best"])},
                     {"peer", peer},
                     {"peer_f1", peer_f1}});
    if (gap < worst_peer_gap)
      worst_peer_gap = gap, worst_peer_pair = row["pair"].get<std::string>();
  }
  summary["best_against_peers"] = peers;
  if (f1.count("best") && f1.count("magsac")) {
    const double gain = summary["mean_f1"]["best"]["mean"].get<double>() -
                        summary["mean_f1"]["magsac"]["mean"].get<double>();
    summary["measurements"] = {{"mean_f1_best_minus_magsac", gain},
                               {"worst_pair_f1_best_minus_magsac", worst},
                               {"worst_pair", worst_pair}};
  }
  if (!peers.empty()) {
    double strongest_mean = -1.0;
    std::string strongest;
    for (const auto& [name, value] : summary["mean_f1"].items()) {
      if (name == "best" || name == "vote_ransac") continue;
      if (value["pairs"] != summary["mean_f1"]["best"]["pairs"]) continue;  // not on every pair
      if (value["mean"].get<double>() > strongest_mean) {
        strongest_mean = value["mean"].get<double>(), strongest = name;
      }
    }
    summary["measurements"]["worst_pair_f1_best_minus_best_peer"] = worst_peer_gap;
    summary["measurements"]["worst_peer_pair"] = worst_peer_pair;
    if (!strongest.empty()) {
      summary["measurements"]["mean_f1_best_minus_strongest_peer"] =
          summary["mean_f1"]["best"]["mean"].get<double>() - strongest_mean;
      summary["measurements"]["strongest_peer"] = strongest;
    }
  }
  return summary;
}

std::string summaryMarkdown(const nlohmann::json& summary) {
  std::ostringstream md;
  size_t pairs = 0;
  for (const auto& [name, value] : summary["mean_f1"].items()) {
    pairs = std::max(pairs, value["pairs"].get<size_t>());
  }
  md << "\nMean F1 over the " << pairs << " pairs (a filter that keeps nothing scores 0):";
  const char* separator = " ";
  for (const auto& [name, value] : summary["mean_f1"].items()) {
    md << separator << name << ' ' << cell(value["mean"]);
    if (value["pairs"].get<size_t>() < pairs) md << " (the " << value["pairs"] << " calibrated)";
    separator = ", ";
  }
  md << ".\n\n";
  if (summary.contains("best_against_peers") && !summary["best_against_peers"].empty()) {
    md << "`best` against the strongest other filter of each pair (vote_ransac is `best`):\n\n"
       << "| pair | best F1 | strongest other | its F1 | best - other |\n"
       << "| --- | --- | --- | --- | --- |\n";
    for (const auto& peer : summary["best_against_peers"]) {
      md << "| " << peer["pair"].get<std::string>() << " | " << cell(peer["best_f1"]) << " | "
         << peer["peer"].get<std::string>() << " | " << cell(peer["peer_f1"]) << " | "
         << cell(peer["best_f1"].get<double>() - peer["peer_f1"].get<double>()) << " |\n";
    }
    md << "\n";
  }
  if (summary.contains("measurements")) md << measurementsMarkdown(summary["measurements"]);
  return md.str();
}

/// A count: as it is for one run, with one decimal for a mean over seeds.
std::string countCell(const nlohmann::json& value) {
  if (value.is_null()) return "-";
  if (value.is_number_integer()) return std::to_string(value.get<long long>());
  std::ostringstream out;
  out << std::fixed << std::setprecision(1) << value.get<double>();
  return out.str();
}

std::string markdown(const nlohmann::json& rows, const nlohmann::json& skipped) {
  std::ostringstream md;
  md << "Written by `sift_hull_bench evaluate-filters --write docs/EVALUATION.md` on " << todayUtc()
     << ". P = precision, R = recall of the correct putatives, F1; default thresholds; ransac, "
        "magsac, guided, vote_ransac and best: means over seeds 0 to 4.\n\n"
     << "| pair | ratio | putative (correct / wrong / unknown) | filter | kept | P | R | F1 | "
        "mismatches removed |\n| --- | --- | --- | --- | --- | --- | --- | --- | --- |\n";
  for (const auto& row : rows) {
    const auto& truth = row["ground_truth"];
    for (const auto& [name, run] : row["filters"].items()) {
      md << "| " << row["pair"].get<std::string>() << " | " << row["ratio"] << " | "
         << row["putative"] << " (" << truth["correct"] << " / " << truth["wrong"] << " / "
         << truth["unknown"] << ") | " << name << " | " << countCell(run["kept"]) << " | "
         << cell(run["precision"]) << " | " << cell(run["recall"]) << " | " << cell(run["f1"])
         << " | " << countCell(run["mismatches_removed"]) << " |\n";
    }
  }
  for (const auto& reason : skipped) md << "\nSkipped: " << reason.get<std::string>() << "\n";
  return md.str();
}

std::vector<std::string> filterList(const std::string& text) {
  std::vector<std::string> names;
  std::istringstream in(text);
  for (std::string name; std::getline(in, name, ',');) {
    try {
      makeFilter(name, FilterConfigs());
    } catch (const std::invalid_argument& error) {
      throw UsageError(std::string("--filters: ") + error.what());
    }
    names.push_back(name);
  }
  if (names.empty()) throw UsageError("--filters: no filter named (give at least one)");
  return names;
}

}  // namespace

int runEvaluateFilters(const std::vector<std::string>& args) {
  ArgParser parser("evaluate-filters",
                   "Scores every filter against ground truth: Middlebury Teddy (ratio 0.8, 0.9,\n"
                   "1.0), Oxford graf 1-2 to 1-5 (ratio 0.8), a synthetic scene pair, a pair with\n"
                   "two motions, one with a strong rotation and zoom, and optical zooms of 2, 2.5\n"
                   "and 3 with a rotation of 30 degrees.");
  parser.addOption("data", "DIR", "real data root", defaultDataRoot());
  parser.addOption("write", "FILE", "replace the evaluate-filters section of this Markdown file");
  parser.addOption("filters", "LIST", "comma-separated filters to score (default: all)");
  addFilterOptions(&parser);
  parser.addFlag("json", "print the result as one JSON object");
  if (!parser.parse(args)) return 0;
  const std::string root = parser.has("data") ? parser.get("data") : "";
  const FilterConfigs configs = filterConfigsFromArgs(parser);
  std::vector<std::string> filters =
      parser.has("filters") ? filterList(parser.get("filters")) : filterNames();
  nlohmann::json rows = nlohmann::json::array(), skipped = nlohmann::json::array();
  std::string why_not;
  // COLMAP's own verification, the user's peer, when its program is installed.
  if (!parser.has("filters")) {
    if (colmapAvailable("colmap", &why_not)) {
      filters.push_back("colmap");
    } else {
      skipped.push_back("the colmap filter: " + why_not);
    }
  }
  for (double ratio : {0.8, 0.9, 1.0}) {
    MatchOptions options;
    options.matching.ratio = ratio;
    if (const auto teddy = teddyPair(root, options, &why_not)) {
      rows.push_back(evaluatePair(*teddy, ratio, filters, configs));
    } else if (ratio == 0.8) {
      skipped.push_back(why_not);
    }
  }
  for (int n : {2, 3, 4, 5}) {
    if (const auto graf = grafPair(root, n, MatchOptions(), &why_not)) {
      rows.push_back(evaluatePair(*graf, MatchConfig().ratio, filters, configs));
    } else if (n == 2) {
      skipped.push_back(why_not);
    }
  }
  const double ratio = MatchConfig().ratio;
  rows.push_back(evaluatePair(scenePair(MatchOptions()), ratio, filters, configs));
  rows.push_back(
      evaluatePair(warpedEvaluationPair("synthetic, two motions", twoMotionPair(), MatchOptions()),
                   ratio, filters, configs));
  rows.push_back(evaluatePair(warpedEvaluationPair("synthetic, rotation 60 deg and zoom 1.6",
                                                   rotationZoomPair(60.0, 1.6), MatchOptions()),
                              ratio, filters, configs));
  for (double zoom : {2.0, 2.5, 3.0}) {
    std::ostringstream name;
    name << "synthetic, optical zoom " << zoom << " and rotation 30 deg";
    rows.push_back(
        evaluatePair(warpedEvaluationPair(name.str(), opticalZoomPair(30.0, zoom), MatchOptions()),
                     ratio, filters, configs));
  }
  const nlohmann::json summary = summaryJson(rows);
  const nlohmann::json result = {{"pairs", rows}, {"skipped", skipped}, {"summary", summary}};
  const std::string text = markdown(rows, skipped) + summaryMarkdown(summary);
  if (parser.has("write")) replaceMarkedSection(parser.get("write"), "evaluate-filters", text);
  printResult(parser.flag("json"), result, text);
  return 0;
}

}  // namespace cli
}  // namespace sift_hull
