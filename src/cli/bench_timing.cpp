#include "bench_timing.h"

#include <sys/resource.h>

#include <algorithm>
#include <chrono>
#include <iomanip>
#include <sstream>
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
  return median(times);
}

double median(std::vector<double> values) {
  if (values.empty()) return 0.0;
  std::nth_element(values.begin(), values.begin() + values.size() / 2, values.end());
  return values[values.size() / 2];
}

std::string fixed(double value, int digits) {
  std::ostringstream out;
  out << std::fixed << std::setprecision(digits) << value;
  return out.str();
}

std::string targetsMarkdown(const nlohmann::json& targets) {
  std::ostringstream out;
  out << "### Targets\n\n";
  for (const auto& [name, value] : targets.items()) {
    out << "- `" << name << "`: " << value.dump() << '\n';
  }
  return out.str();
}

double peakMemoryMiB() {
  rusage usage{};
  getrusage(RUSAGE_SELF, &usage);
  return usage.ru_maxrss / 1024.0;  // ru_maxrss is in KiB on Linux
}

}  // namespace cli
}  // namespace sift_hull
