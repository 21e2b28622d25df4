#pragma once

#include <chrono>
#include <cmath>
#include <cstdio>
#include <limits>
#include <mutex>
#include <optional>
#include <string>
#include <utility>
#include <vector>

namespace sift_hull {

/// Notices inputs that arrive but do not pair (a synchronizer's inputs whose stamps differ, masks
/// whose poses never come): counts each input's arrivals since the last pair; once some have
/// waited `patience_s` without a pair while every input has arrived since (or never at all),
/// problem() says which arrived, how many, their newest stamps, and `hint` (what pairing needs).
/// Thread-safe.
class PairingWatch {
 public:
  using Clock = std::chrono::steady_clock;

  PairingWatch(std::vector<std::string> inputs, double patience_s, std::string hint)
      : patience_(
            std::chrono::duration_cast<Clock::duration>(std::chrono::duration<double>(patience_s))),
        patience_s_(patience_s),
        hint_(std::move(hint)) {
    for (std::string& name : inputs) inputs_.push_back({std::move(name)});
  }

  /// A message of input `input` (its index among the names given) with header stamp `stamp_s`.
  void arrived(size_t input, double stamp_s, Clock::time_point now) {
    std::lock_guard<std::mutex> lock(mutex_);
    if (input >= inputs_.size()) return;
    ++inputs_[input].unpaired;
    ++inputs_[input].received;
    inputs_[input].ever = true;
    inputs_[input].newest_stamp_s = stamp_s;
    if (!first_unpaired_) first_unpaired_ = now;
  }

  /// The inputs paired: what arrived so far is accounted for.
  void paired() {
    std::lock_guard<std::mutex> lock(mutex_);
    for (Input& input : inputs_) input.unpaired = 0;
    ++pairs_;
    first_unpaired_.reset();
  }

  /// One input's messages since the start, and how many of them were left out of every pair: the
  /// synchroniser dropped them (its queue full, or no partner) or still holds them.
  struct Total {
    std::string name;
    size_t received = 0, unpaired = 0;
  };

  std::vector<Total> totals() const {
    std::lock_guard<std::mutex> lock(mutex_);
    std::vector<Total> totals;
    for (const Input& input : inputs_) {
      totals.push_back({input.name, input.received,
                        input.received > pairs_ ? input.received - pairs_ : size_t{0}});
    }
    return totals;
  }

  /// Empty while the inputs pair (or nothing arrives); else why they do not, e.g. "silhouette (12
  /// since the last pair, newest stamp 10.000 s) and camera_info (12, newest 10.005 s) arrive but
  /// have not paired for 5 s: HINT".
  std::string problem(Clock::time_point now) const {
    std::lock_guard<std::mutex> lock(mutex_);
    if (!first_unpaired_ || now - *first_unpaired_ < patience_) return "";
    // An input that came before but not since the last pair is idle (masks made now and then
    // while camera_info streams), not failing to pair; one that never came is missing.
    for (const Input& input : inputs_) {
      if (input.unpaired == 0 && input.ever) return "";
    }
    std::string arrivals;
    for (const Input& input : inputs_) {
      if (!arrivals.empty()) arrivals += ", ";
      arrivals += input.name + " (" + std::to_string(input.unpaired);
      if (input.unpaired > 0) arrivals += ", newest stamp " + seconds(input.newest_stamp_s);
      arrivals += ")";
    }
    return "inputs arrive but have not paired for " + seconds(patience_s_, 0) +
           ", messages since the last pair: " + arrivals + ": " + hint_;
  }

 private:
  struct Input {
    std::string name;
    size_t unpaired = 0;  ///< since the last pair
    size_t received = 0;  ///< since the start
    bool ever = false;    ///< arrived since the start
    double newest_stamp_s = std::numeric_limits<double>::quiet_NaN();
  };

  static std::string seconds(double value, int decimals = 3) {
    char text[64];
    std::snprintf(text, sizeof(text), "%.*f s", decimals, value);
    return text;
  }

  const Clock::duration patience_;
  const double patience_s_;
  const std::string hint_;
  mutable std::mutex mutex_;
  std::vector<Input> inputs_;
  size_t pairs_ = 0;
  std::optional<Clock::time_point> first_unpaired_;
};

}  // namespace sift_hull
