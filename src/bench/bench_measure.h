#pragma once

#include <functional>
#include <string>
#include <vector>

namespace sift_hull {
namespace cli {

/// The middle value (the upper one of an even count); 0 for none.
double median(std::vector<double> values);

/// Median wall time in ms of `run` over repeats: at least `min_repeats`, more while the total is
/// under `budget_ms`, at most 101.
double medianMs(const std::function<void()>& run, double budget_ms, int min_repeats = 3);

/// Resets the peak resident memory that residentPeakMiB() reads (writes 5 to
/// /proc/self/clear_refs); false when the kernel refuses.
bool resetResidentPeak();
/// VmHWM of /proc/self/status in MiB: the peak resident memory since the start or since the last
/// resetResidentPeak(); 0 when unreadable.
double residentPeakMiB();

/// The CPU's "model name" in /proc/cpuinfo, or "unknown".
std::string cpuModel();

}  // namespace cli
}  // namespace sift_hull
