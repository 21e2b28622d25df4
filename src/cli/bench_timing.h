#pragma once

#include <functional>

namespace sift_hull {
namespace cli {

/// Median wall time in ms of `run` over repeats: at least `min_repeats`, more while the total is
/// under `budget_ms`, at most 101.
double medianMs(const std::function<void()>& run, double budget_ms, int min_repeats = 3);

/// The process's peak resident memory so far, in MiB (getrusage).
double peakMemoryMiB();

}  // namespace cli
}  // namespace sift_hull
