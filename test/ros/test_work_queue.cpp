// The nodes' bounded work queue: every item processed while the workers keep up; under a faster
// input the oldest waiting items are dropped and counted, and the queue never grows past its bound.

#include <gtest/gtest.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <future>
#include <set>
#include <stdexcept>
#include <string>

#include "lib/work_queue.h"

namespace sift_hull {
namespace {

TEST(WorkQueue, ProcessesEveryItemWhenTheWorkersKeepUp) {
  std::mutex mutex;
  std::set<int> seen;
  WorkQueue<int> queue(4, 2, [&](int& item) {
    std::lock_guard<std::mutex> lock(mutex);
    seen.insert(item);
  });
  for (int i = 0; i < 100; ++i) {
    queue.push(i);
    if (i % 4 == 3) queue.waitIdle();
  }
  queue.waitIdle();
  EXPECT_EQ(seen.size(), 100u);
  const auto counts = queue.counts();
  EXPECT_EQ(counts.pushed, 100u);
  EXPECT_EQ(counts.done, 100u);
  EXPECT_EQ(counts.dropped, 0u);
}

TEST(WorkQueue, DropsTheOldestWaitingItemsWhenFullAndCountsThem) {
  std::promise<void> release;
  std::shared_future<void> released = release.get_future().share();
  std::promise<void> first_taken;
  std::vector<int> processed;
  WorkQueue<int> queue(3, 1, [&](int& item) {
    if (item == 0) {
      first_taken.set_value();
      released.wait();  // hold the only worker while the input runs ahead
    }
    processed.push_back(item);
  });
  queue.push(0);
  first_taken.get_future().wait();
  size_t most_waiting = 0;
  int refused_room = 0;
  for (int i = 1; i <= 10; ++i) {
    refused_room += !queue.push(i);
    most_waiting = std::max(most_waiting, queue.counts().waiting);
  }
  EXPECT_EQ(most_waiting, 3u);  // bounded
  EXPECT_EQ(refused_room, 7);
  release.set_value();
  queue.waitIdle();
  EXPECT_EQ(processed, (std::vector<int>{0, 8, 9, 10}));  // the newest survive
  EXPECT_EQ(queue.clear(), 0u);
  const auto counts = queue.counts();
  EXPECT_EQ(counts.pushed, 11u);
  EXPECT_EQ(counts.dropped, 7u);
  EXPECT_EQ(counts.done, 4u);
  EXPECT_EQ(counts.waiting, 0u);
}

TEST(WorkQueue, ClearDiscardsTheWaitingItemsWithoutCountingThemDropped) {
  std::promise<void> release;
  std::shared_future<void> released = release.get_future().share();
  std::promise<void> first_taken;
  std::vector<int> processed;
  WorkQueue<int> queue(5, 1, [&](int& item) {
    if (item == 0) {
      first_taken.set_value();
      released.wait();
    }
    processed.push_back(item);
  });
  queue.push(0);
  first_taken.get_future().wait();
  queue.push(1);
  queue.push(2);
  EXPECT_EQ(queue.clear(), 2u);
  queue.push(3);
  release.set_value();
  queue.waitIdle();
  EXPECT_EQ(processed, (std::vector<int>{0, 3}));
  EXPECT_EQ(queue.counts().dropped, 0u);
}

TEST(WorkQueue, CountsAThrowingItemAsFailedAndGoesOn) {
  std::vector<int> processed;
  WorkQueue<int> queue(4, 1, [&](int& item) {
    if (item == 1) throw std::runtime_error("bad item");
    processed.push_back(item);
  });
  for (int i = 0; i < 3; ++i) {
    queue.push(i);
    queue.waitIdle();
  }
  EXPECT_EQ(processed, (std::vector<int>{0, 2}));
  EXPECT_EQ(queue.counts().failed, 1u);
  EXPECT_EQ(queue.counts().done, 3u);
}

TEST(WorkQueue, RunsCommandsBeforeWaitingItemsAndCallWaitsForItsCommand) {
  std::promise<void> release;
  std::shared_future<void> released = release.get_future().share();
  std::promise<void> first_taken;
  std::vector<std::string> order;  // written by the worker only
  WorkQueue<int> queue(5, 1, [&](int& item) {
    if (item == 0) {
      first_taken.set_value();
      released.wait();
    }
    order.push_back("item " + std::to_string(item));
  });
  queue.push(0);
  first_taken.get_future().wait();
  queue.push(1);
  EXPECT_TRUE(queue.post([&] { order.push_back("command"); }));
  EXPECT_FALSE(queue.call([] {}, 0.05)) << "the worker is busy with item 0: the deadline passes";
  release.set_value();
  EXPECT_TRUE(queue.call([&] { order.push_back("called"); }, 5.0));
  queue.waitIdle();
  // The command (posted while item 1 waited) ran before item 1; each call ran once.
  ASSERT_GE(order.size(), 4u);
  EXPECT_EQ(order[0], "item 0");
  EXPECT_EQ(order[1], "command");
  EXPECT_EQ(std::count(order.begin(), order.end(), "called"), 1);
  EXPECT_EQ(std::count(order.begin(), order.end(), "item 1"), 1);
}

TEST(WorkQueue, RefusesCommandsBeyondItsBoundAndAfterStop) {
  std::promise<void> release;
  std::shared_future<void> released = release.get_future().share();
  std::promise<void> first_taken;
  WorkQueue<int> queue(1, 1, [&](int&) {
    first_taken.set_value();
    released.wait();
  });
  queue.push(0);
  first_taken.get_future().wait();
  for (size_t i = 0; i < WorkQueue<int>::kMaxCommands; ++i) EXPECT_TRUE(queue.post([] {}));
  EXPECT_FALSE(queue.post([] {})) << "commands are bounded";
  release.set_value();
  queue.stop();
  EXPECT_FALSE(queue.post([] {}));
  EXPECT_FALSE(queue.call([] {}, 0.1));
}

TEST(WorkQueue, StopsAfterTheItemInHandAndDiscardsTheWaitingOnes) {
  std::promise<void> release;
  std::shared_future<void> released = release.get_future().share();
  std::promise<void> first_taken;
  std::atomic<int> done{0};
  WorkQueue<int> queue(10, 1, [&](int& item) {
    if (item == 0) {
      first_taken.set_value();
      released.wait();
    }
    ++done;
  });
  for (int i = 0; i < 10; ++i) queue.push(i);
  first_taken.get_future().wait();
  std::thread stopper([&] { queue.stop(); });
  while (queue.counts().waiting > 0) std::this_thread::yield();  // stop() has discarded them
  release.set_value();
  stopper.join();
  EXPECT_EQ(done.load(), 1);
  queue.push(11);  // ignored once stopped
  EXPECT_EQ(queue.counts().waiting, 0u);
}

}  // namespace
}  // namespace sift_hull
