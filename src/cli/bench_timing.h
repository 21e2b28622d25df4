#pragma once

#include <chrono>

namespace sift_hull {
namespace cli {

/// The process's peak resident memory so far, in MiB (getrusage).
double peakMemoryMiB();

/// Wall milliseconds since `start` (steady clock).
double millisecondsSince(std::chrono::steady_clock::time_point start);

}  // namespace cli
}  // namespace sift_hull
