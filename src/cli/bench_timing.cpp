#include "bench_timing.h"

#include <sys/resource.h>

#include <algorithm>
#include <chrono>
#include <vector>

namespace sift_hull {
namespace cli {

double medianMs(const std::function<void()>& run, double budget_ms, int min_repeats) {
  std::vector<double> times;
  double total = 0.0;
  while (static_cast<int>(times.size()) < min_repeats ||
         (total < budget_ms && times.size() < 101)) {
    const auto start = std::chrono::steady_clock::now();
    run();
    const auto stop = std::chrono::steady_clock::now();
    times.push_back(std::chrono::duration<double, std::milli>(stop - start).count());
    total += times.back();
  }
  std::nth_element(times.begin(), times.begin() + times.size() / 2, times.end());
  return times[times.size() / 2];
}

double peakMemoryMiB() {
  rusage usage{};
  getrusage(RUSAGE_SELF, &usage);
  return usage.ru_maxrss / 1024.0;  // ru_maxrss is in KiB on Linux
}

}  // namespace cli
}  // namespace sift_hull
