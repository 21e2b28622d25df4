// evaluate-filters: precision, recall and F1 of every filter on real pairs with ground truth
// (Teddy at three ratios, graf 1-2, 1-3, 1-4) and on a synthetic scene pair.

#include <iomanip>
#include <sstream>

#include "args.h"
#include "commands.h"
#include "match_eval.h"
#include "pair_data.h"
#include "sift_hull/features/labelled_matches.h"
#include "sift_hull/filters/filter.h"
#include "sift_hull/synthetic/scene.h"

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

nlohmann::json evaluatePair(const EvaluationPair& pair, double ratio) {
  const LabelledMatches& matches = pair.matches;
  nlohmann::json row = {{"pair", pair.name}, {"ratio", ratio}, {"putative", matches.truth.size()}};
  row["ground_truth"] = truthJson("", matches.truth);
  row["ground_truth"].erase("kind");
  row["filters"] = nlohmann::json::object();
  for (const std::string& name : filterNames()) {
    if (name == "epipolar" && !matches.putative.F_right_left) continue;
    const FilterRun run = timedRun(*makeFilter(name, FilterConfigs()), matches.putative);
    row["filters"][name] = filterRunJson(run, &matches.truth);
  }
  return row;
}

std::string cell(const nlohmann::json& value) {
  if (value.is_null()) return "-";
  std::ostringstream out;
  out << std::fixed << std::setprecision(3) << value.get<double>();
  return out.str();
}

std::string markdown(const nlohmann::json& rows, const nlohmann::json& skipped) {
  std::ostringstream md;
  md << "Written by `sift_hull evaluate-filters --write docs/EVALUATION.md` on " << todayUtc()
     << ". P = precision, R = recall of the correct putatives, F1; default thresholds.\n\n"
     << "| pair | ratio | putative (correct / wrong / unknown) | filter | kept | P | R | F1 | "
        "mismatches removed |\n| --- | --- | --- | --- | --- | --- | --- | --- | --- |\n";
  for (const auto& row : rows) {
    const auto& truth = row["ground_truth"];
    for (const auto& [name, run] : row["filters"].items()) {
      md << "| " << row["pair"].get<std::string>() << " | " << row["ratio"] << " | "
         << row["putative"] << " (" << truth["correct"] << " / " << truth["wrong"] << " / "
         << truth["unknown"] << ") | " << name << " | " << run["kept"] << " | "
         << cell(run["precision"]) << " | " << cell(run["recall"]) << " | " << cell(run["f1"])
         << " | " << run["mismatches_removed"] << " |\n";
    }
  }
  for (const auto& reason : skipped) md << "\nSkipped: " << reason.get<std::string>() << "\n";
  return md.str();
}

}  // namespace

int runEvaluateFilters(const std::vector<std::string>& args) {
  ArgParser parser("evaluate-filters",
                   "Scores every filter against ground truth: Middlebury Teddy (ratio 0.8, 0.9,\n"
                   "1.0), Oxford graf 1-2, 1-3, 1-4 (ratio 0.8) and a synthetic scene pair.");
  parser.addOption("data", "DIR", "real data root", defaultDataRoot());
  parser.addOption("write", "FILE", "replace the evaluate-filters section of this Markdown file");
  parser.addFlag("json", "print the result as one JSON object");
  if (!parser.parse(args)) return 0;
  const std::string root = parser.has("data") ? parser.get("data") : "";
  nlohmann::json rows = nlohmann::json::array(), skipped = nlohmann::json::array();
  std::string why_not;
  for (double ratio : {0.8, 0.9, 1.0}) {
    MatchOptions options;
    options.matching.ratio = ratio;
    if (const auto teddy = teddyPair(root, options, &why_not)) {
      rows.push_back(evaluatePair(*teddy, ratio));
    } else if (ratio == 0.8) {
      skipped.push_back(why_not);
    }
  }
  for (int n : {2, 3, 4}) {
    if (const auto graf = grafPair(root, n, MatchOptions(), &why_not)) {
      rows.push_back(evaluatePair(*graf, MatchConfig().ratio));
    } else if (n == 2) {
      skipped.push_back(why_not);
    }
  }
  rows.push_back(evaluatePair(scenePair(MatchOptions()), MatchConfig().ratio));
  const nlohmann::json result = {{"pairs", rows}, {"skipped", skipped}};
  const std::string text = markdown(rows, skipped);
  if (parser.has("write")) replaceMarkedSection(parser.get("write"), "evaluate-filters", text);
  printResult(parser.flag("json"), result, text);
  return 0;
}

}  // namespace cli
}  // namespace sift_hull
