#pragma once

#include <algorithm>
#include <condition_variable>
#include <cstdint>
#include <deque>
#include <functional>
#include <future>
#include <memory>
#include <mutex>
#include <thread>
#include <vector>

namespace sift_hull {

/// A queue of bounded length shared between threads: when full, the oldest item makes room.
template <typename Item>
class BoundedQueue {
 public:
  explicit BoundedQueue(size_t capacity) : capacity_(std::max<size_t>(capacity, 1)) {}
  /// Queues `item`; false when the oldest item was dropped to make room.
  bool push(Item item) {
    std::lock_guard<std::mutex> lock(mutex_);
    items_.push_back(std::move(item));
    if (items_.size() <= capacity_) return true;
    items_.pop_front();
    return false;
  }
  /// The oldest item, or false when there is none.
  bool pop(Item* item) {
    std::lock_guard<std::mutex> lock(mutex_);
    if (items_.empty()) return false;
    *item = std::move(items_.front());
    items_.pop_front();
    return true;
  }
  /// Drops every item; returns how many there were.
  size_t clear() {
    std::lock_guard<std::mutex> lock(mutex_);
    const size_t size = items_.size();
    items_.clear();
    return size;
  }

 private:
  const size_t capacity_;
  std::mutex mutex_;
  std::deque<Item> items_;
};

/// What a WorkQueue has seen so far.
struct WorkCounts {
  uint64_t pushed = 0;   ///< items queued
  uint64_t dropped = 0;  ///< items dropped from a full queue, unprocessed
  uint64_t done = 0;     ///< items processed
  uint64_t failed = 0;   ///< of those, items whose processing threw
  size_t waiting = 0;    ///< items in the queue now
};

/// Work handed from subscriber callbacks to worker threads through a queue of bounded length.
/// When the queue is full, the oldest waiting item is dropped and counted: a callback never waits
/// for the work, and memory stays bounded however fast the input comes.
template <typename Item>
class WorkQueue {
 public:
  /// `process` runs on one of `workers` threads; it should not throw (what it throws is counted
  /// as failed and otherwise ignored, so that the worker lives on).
  WorkQueue(size_t capacity, int workers, std::function<void(Item&)> process)
      : capacity_(std::max<size_t>(capacity, 1)), process_(std::move(process)) {
    for (int i = 0; i < std::max(workers, 1); ++i) workers_.emplace_back([this] { work(); });
  }
  WorkQueue(const WorkQueue&) = delete;
  WorkQueue& operator=(const WorkQueue&) = delete;
  ~WorkQueue() { stop(); }

  /// Queues `item`; returns false when the oldest waiting item was dropped to make room for it.
  /// After stop(), items are ignored.
  bool push(Item item) {
    bool made_room = false;
    {
      std::lock_guard<std::mutex> lock(mutex_);
      if (stopping_) return true;
      if (queue_.size() >= capacity_) {
        queue_.pop_front();
        ++counts_.dropped;
        made_room = true;
      }
      queue_.push_back(std::move(item));
      ++counts_.pushed;
    }
    ready_.notify_one();
    return !made_room;
  }

  WorkCounts counts() const {
    std::lock_guard<std::mutex> lock(mutex_);
    WorkCounts counts = counts_;
    counts.waiting = queue_.size();
    return counts;
  }

  /// Runs `task` on a worker before the next item (commands run in the order posted, before any
  /// waiting item); false, and nothing queued, when kMaxCommands wait already or after stop().
  /// What a task throws is ignored.
  bool post(std::function<void()> task) {
    {
      std::lock_guard<std::mutex> lock(mutex_);
      if (stopping_ || commands_.size() >= kMaxCommands) return false;
      commands_.push_back(std::move(task));
    }
    ready_.notify_one();
    return true;
  }
  static constexpr size_t kMaxCommands = 64;

  /// post(task), then waits for it at most timeout_s: false when it had not run by then (it
  /// still runs later: it must own what it uses) or could not be queued.
  bool call(std::function<void()> task, double timeout_s) {
    auto done = std::make_shared<std::promise<void>>();
    std::future<void> finished = done->get_future();
    const bool queued = post([task = std::move(task), done] {
      try {
        task();
      } catch (...) {  // never out of the worker
      }
      done->set_value();
    });
    return queued && finished.wait_for(std::chrono::duration<double>(timeout_s)) ==
                         std::future_status::ready;
  }

  /// Discards the waiting items (not counted as dropped); returns how many there were.
  size_t clear() {
    std::lock_guard<std::mutex> lock(mutex_);
    const size_t waiting = queue_.size();
    queue_.clear();
    idle_.notify_all();
    return waiting;
  }

  /// Blocks until no item waits and no worker is busy.
  void waitIdle() {
    std::unique_lock<std::mutex> lock(mutex_);
    idle_.wait(lock, [this] { return queue_.empty() && commands_.empty() && busy_ == 0; });
  }

  /// Lets the workers finish the items in hand, discards the waiting ones and joins the workers.
  void stop() {
    {
      std::lock_guard<std::mutex> lock(mutex_);
      stopping_ = true;
      queue_.clear();
      commands_.clear();
    }
    ready_.notify_all();
    idle_.notify_all();
    for (std::thread& worker : workers_) {
      if (worker.joinable()) worker.join();
    }
  }

 private:
  void work() {
    std::unique_lock<std::mutex> lock(mutex_);
    while (true) {
      ready_.wait(lock, [this] { return stopping_ || !queue_.empty() || !commands_.empty(); });
      if (stopping_) return;
      if (!commands_.empty()) {
        runCommand(&lock);
        continue;
      }
      Item item = std::move(queue_.front());
      queue_.pop_front();
      ++busy_;
      lock.unlock();
      const bool failed = !processes(item);
      lock.lock();
      --busy_;
      ++counts_.done;
      counts_.failed += failed;
      idle_.notify_all();
    }
  }

  void runCommand(std::unique_lock<std::mutex>* lock) {
    std::function<void()> task = std::move(commands_.front());
    commands_.pop_front();
    ++busy_;
    lock->unlock();
    try {
      task();
    } catch (...) {
    }
    lock->lock();
    --busy_;
    idle_.notify_all();
  }

  bool processes(Item& item) {
    try {
      process_(item);
      return true;
    } catch (...) {
      return false;
    }
  }

  const size_t capacity_;
  const std::function<void(Item&)> process_;
  mutable std::mutex mutex_;
  std::condition_variable ready_, idle_;
  std::deque<Item> queue_;
  std::deque<std::function<void()>> commands_;
  WorkCounts counts_;
  int busy_ = 0;
  bool stopping_ = false;
  std::vector<std::thread> workers_;  // last: started once everything above exists
};

}  // namespace sift_hull
