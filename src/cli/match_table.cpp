#include "match_table.h"

#include <cmath>
#include <fstream>
#include <iomanip>
#include <nlohmann/json.hpp>
#include <sstream>
#include <stdexcept>

#include "args.h"

namespace sift_hull {
namespace cli {
namespace {

bool endsWith(const std::string& text, const std::string& suffix) {
  return text.size() >= suffix.size() &&
         text.compare(text.size() - suffix.size(), suffix.size(), suffix) == 0;
}

const char* truthName(MatchTruth truth) {
  switch (truth) {
    case MatchTruth::kCorrect:
      return "correct";
    case MatchTruth::kWrong:
      return "wrong";
    default:
      return "unknown";
  }
}

/// The columns of one row, in order, as JSON values (numbers, strings, null for NaN).
std::vector<std::pair<std::string, nlohmann::json>> row(const PutativeMatches& input, size_t m,
                                                        const std::vector<FilterRun>& runs,
                                                        const std::vector<MatchTruth>* truth) {
  const cv::KeyPoint &l = input.left(m), &r = input.right(m);
  const auto number = [](double v) { return std::isfinite(v) ? nlohmann::json(v) : nullptr; };
  std::vector<std::pair<std::string, nlohmann::json>> columns = {
      {"match", m},
      {"left_x", number(l.pt.x)},
      {"left_y", number(l.pt.y)},
      {"left_size", number(l.size)},
      {"left_angle", number(l.angle)},
      {"right_x", number(r.pt.x)},
      {"right_y", number(r.pt.y)},
      {"right_size", number(r.size)},
      {"right_angle", number(r.angle)},
      {"descriptor_distance", number(input.matches[m].distance)}};
  if (truth) columns.emplace_back("truth", truthName((*truth)[m]));
  for (const FilterRun& run : runs) {
    columns.emplace_back(run.name + "_keep", int(run.result.keep[m]));
    columns.emplace_back(run.name + "_score", number(run.result.score[m]));
  }
  return columns;
}

std::string csvCell(const nlohmann::json& value) {
  if (value.is_null()) return "";
  if (value.is_string()) return value.get<std::string>();
  if (value.is_number_float()) {
    std::ostringstream out;
    out << std::setprecision(9) << value.get<double>();
    return out.str();
  }
  return value.dump();
}

}  // namespace

void checkMatchTablePath(const std::string& path) {
  if (!endsWith(path, ".csv") && !endsWith(path, ".json")) {
    throw UsageError("--out-matches: the file must end in .csv or .json, not '" + path + "'");
  }
}

void writeMatchTable(const std::string& path, const PutativeMatches& input,
                     const std::vector<FilterRun>& runs, const std::vector<MatchTruth>* truth) {
  checkMatchTablePath(path);
  const bool csv = endsWith(path, ".csv");
  std::ofstream out(path);
  if (!out) throw std::runtime_error(path + ": cannot write the match table");
  nlohmann::json rows = nlohmann::json::array();
  if (csv) {
    std::vector<std::string> names = {
        "match",   "left_x",  "left_y",     "left_size",   "left_angle",
        "right_x", "right_y", "right_size", "right_angle", "descriptor_distance"};
    if (truth) names.push_back("truth");
    for (const FilterRun& run : runs)
      names.push_back(run.name + "_keep"), names.push_back(run.name + "_score");
    for (size_t c = 0; c < names.size(); ++c) out << (c ? "," : "") << names[c];
    out << '\n';
  }
  for (size_t m = 0; m < input.matches.size(); ++m) {
    const auto columns = row(input, m, runs, truth);
    if (csv) {
      for (size_t c = 0; c < columns.size(); ++c)
        out << (c ? "," : "") << csvCell(columns[c].second);
      out << '\n';
    } else {
      nlohmann::json object;
      for (const auto& [name, value] : columns) object[name] = value;
      rows.push_back(object);
    }
  }
  if (!csv) out << rows.dump(1) << '\n';
  if (!out) throw std::runtime_error(path + ": cannot write the match table");
}

}  // namespace cli
}  // namespace sift_hull
