#pragma once

#include <chrono>
#include <functional>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

namespace sift_hull {
namespace cli {

/// The middle value (the upper one of an even count); 0 for none.
double median(std::vector<double> values);

/// `value` with `digits` decimals, for the Markdown tables of the benchmarks.
std::string fixed(double value, int digits);

/// "### Targets" and one line per target: `name`: its JSON (measured, met).
std::string targetsMarkdown(const nlohmann::json& targets);

/// Median wall time in ms of `run` over repeats: at least `min_repeats`, more while the total is
/// under `budget_ms`, at most 101.
double medianMs(const std::function<void()>& run, double budget_ms, int min_repeats = 3);

/// The process's peak resident memory so far, in MiB (getrusage).
double peakMemoryMiB();

/// Resets the peak resident memory that residentPeakMiB() reads (writes 5 to
/// /proc/self/clear_refs); false when the kernel refuses.
bool resetResidentPeak();
/// VmHWM of /proc/self/status in MiB: the peak resident memory since the start or since the last
/// resetResidentPeak(); 0 when unreadable.
double residentPeakMiB();

/// Wall milliseconds since `start` (steady clock).
double millisecondsSince(std::chrono::steady_clock::time_point start);

/// The CPU's "model name" in /proc/cpuinfo, or "unknown".
std::string cpuModel();

}  // namespace cli
}  // namespace sift_hull
