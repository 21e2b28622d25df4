#pragma once

#include <nlohmann/json.hpp>
#include <string>

namespace sift_hull {
namespace cli {

/// `value` with `digits` decimals, for the Markdown tables of the benchmarks.
std::string fixed(double value, int digits);

/// "### Measurements for the targets" and one line per entry of `measurements` (an object of plain
/// names, as in the --json output): `name`: the number with 4 significant digits, or the text.
/// The targets themselves and their verdicts are stated in docs/BENCHMARKS.md and
/// docs/EVALUATION.md, beside the section this goes into, not by the program.
std::string measurementsMarkdown(const nlohmann::json& measurements);

/// Today's date in UTC, YYYY-MM-DD, to stamp measurements written to docs.
std::string todayUtc();

/// Replaces the text between the lines "<!-- begin NAME -->" and "<!-- end NAME -->" of a
/// Markdown file (appending the marked section when missing).
void replaceMarkedSection(const std::string& path, const std::string& name,
                          const std::string& content);

}  // namespace cli
}  // namespace sift_hull
