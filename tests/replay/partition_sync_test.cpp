// SPDX-License-Identifier: MIT
// The partition executor's waits (replay/src/sync.hpp): past the spin budget a wait spins on
// while the thread it waits for runs, parks when that thread sleeps, and does the work its
// idle hook finds while it spins.
#include <gtest/gtest.h>

#include <atomic>
#include <cstdint>
#include <thread>

#include "sync.hpp"

namespace tgraph::replay::detail {
namespace {

constexpr std::int64_t kSpinNs = 20'000;

TEST(PartitionSync, PastTheSpinBudgetAWaitSpinsOnWhileTheThreadItWaitsForRuns) {
  Parking parking(kSpinNs, false, 60'000'000'000);  // a minute: never reached here
  std::atomic<std::uint64_t> c{0};
  const std::atomic<bool> abort{false};
  std::atomic<std::uint32_t> sleeping{0};
  int asked = 0;
  bool parked = true;
  std::int64_t waited = 0;
  // awake() is asked only once the spin budget is spent; the producer "publishes" the
  // value the third time it is asked: the wait must still be spinning then.
  const std::uint64_t v = parking.wait(
      c, [](std::uint64_t s) { return s == 7; }, abort, parked, waited, [] { return false; },
      [&] {
        if (++asked == 3) c.store(7, std::memory_order_release);  // release: a publication
        return true;
      },
      &sleeping);
  EXPECT_EQ(v, 7u);
  EXPECT_GE(asked, 3);
  EXPECT_FALSE(parked);
  EXPECT_GE(waited, kSpinNs);
  EXPECT_EQ(sleeping.load(), 0u);
}

TEST(PartitionSync, AWaitParksOnceTheBudgetIsSpentWhenTheThreadItWaitsForSleeps) {
  Parking parking(kSpinNs, false);
  std::atomic<std::uint64_t> c{0};
  const std::atomic<bool> abort{false};
  std::atomic<std::uint32_t> sleeping{0};
  std::atomic<bool> saw_sleeping{false};
  std::thread producer([&] {
    while (parking.parked() == 0) std::this_thread::yield();
    saw_sleeping = sleeping.load() == 1;  // the waiter says it sleeps while it does
    parking.signal(c, 7);
  });
  bool parked = false;
  std::int64_t waited = 0;
  const std::uint64_t v = parking.wait(
      c, [](std::uint64_t s) { return s == 7; }, abort, parked, waited, [] { return false; },
      [] { return false; }, &sleeping);
  producer.join();
  EXPECT_EQ(v, 7u);
  EXPECT_TRUE(parked);
  EXPECT_TRUE(saw_sleeping.load());
  EXPECT_EQ(sleeping.load(), 0u);
}

TEST(PartitionSync, AnOversubscribedWaitParksAfterItsBudgetWhateverTheOtherThreadDoes) {
  Parking parking(kSpinNs, true);
  std::atomic<std::uint64_t> c{0};
  const std::atomic<bool> abort{false};
  std::thread producer([&] {
    while (parking.parked() == 0) std::this_thread::yield();
    parking.signal(c, 1);
  });
  bool parked = false;
  std::int64_t waited = 0;
  int asked = 0;
  parking.wait(
      c, [](std::uint64_t s) { return s == 1; }, abort, parked, waited, [] { return false; },
      [&] {
        ++asked;
        return true;
      },
      nullptr);
  producer.join();
  EXPECT_TRUE(parked);
  EXPECT_EQ(asked, 0);
}

TEST(PartitionSync, WorkFoundWhileSpinningIsDoneAndNotCountedAsWaiting) {
  Parking parking(kSpinNs, false);
  std::atomic<std::uint64_t> c{0};
  const std::atomic<bool> abort{false};
  int jobs = 0;
  bool parked = true;
  std::int64_t waited = 0;
  const std::int64_t t0 = now_ns();
  // Three jobs of 2 ms each (100 spin budgets), then the value arrives with the fourth call.
  parking.wait(
      c, [](std::uint64_t s) { return s == 1; }, abort, parked, waited,
      [&] {
        if (jobs == 3) {
          c.store(1, std::memory_order_release);
          return false;
        }
        ++jobs;
        const std::int64_t until = now_ns() + 2'000'000;
        while (now_ns() < until) {
        }
        return true;
      },
      [] { return false; }, nullptr);
  const std::int64_t total = now_ns() - t0;
  EXPECT_EQ(jobs, 3);
  EXPECT_FALSE(parked);
  EXPECT_GT(waited, 0);
  EXPECT_LE(waited, total - 5'500'000);  // the 6 ms of jobs are not waiting
}

}  // namespace
}  // namespace tgraph::replay::detail
