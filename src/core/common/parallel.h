#pragma once

#include <atomic>
#include <exception>
#include <mutex>
#include <stdexcept>
#include <string>
#include <system_error>
#include <thread>
#include <vector>

namespace sift_hull {
namespace detail {

/// Runs fn(i) for i in [0, count) on up to `threads` threads, the caller's among them, handing
/// out indices one at a time. Exception-safe: the first exception thrown by fn (std::bad_alloc
/// included) stops the hand-out and is rethrown in the caller once every thread has ended; a
/// thread the system cannot start ends the others and becomes std::runtime_error. Never
/// std::terminate.
template <typename Fn>
void parallelFor(size_t count, int threads, const Fn& fn) {
  std::atomic<size_t> next{0};
  std::atomic<bool> failed{false};
  std::exception_ptr first_error;
  std::mutex error_mutex;
  const auto fail = [&](std::exception_ptr error) {
    std::lock_guard<std::mutex> lock(error_mutex);
    if (!first_error) first_error = error;
    failed = true;
  };
  const auto work = [&]() noexcept {
    try {
      for (size_t i = next++; i < count && !failed; i = next++) fn(i);
    } catch (...) {
      fail(std::current_exception());
    }
  };
  std::vector<std::thread> pool;
  try {
    for (int t = 1; t < threads && static_cast<size_t>(t) < count; ++t) pool.emplace_back(work);
  } catch (const std::exception& e) {  // std::system_error, or std::bad_alloc for the vector
    fail(std::make_exception_ptr(std::runtime_error("cannot start thread " +
                                                    std::to_string(pool.size() + 2) + " of " +
                                                    std::to_string(threads) + ": " + e.what())));
  }
  if (!failed) work();
  for (std::thread& thread : pool) thread.join();
  if (first_error) std::rethrow_exception(first_error);
}

}  // namespace detail
}  // namespace sift_hull
