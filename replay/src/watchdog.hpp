// SPDX-License-Identifier: MIT
// Internal: the replay watchdog (ExecOptions::timeout_ms). A thread of its own samples a
// progress count while a step runs; when it has not changed for the timeout, it ends the
// step through the executor's abort path with a report of what each thread waits for.
#pragma once

#include <atomic>
#include <condition_variable>
#include <cstdint>
#include <exception>
#include <functional>
#include <mutex>
#include <string>
#include <thread>

namespace tgraph::replay::detail {

class Watchdog {
 public:
  /// `progress` sums counters that grow while the step advances; `report` describes where
  /// the threads stand; `abort` ends the step with the exception given. When `exit_if_stuck`,
  /// a step that still has not ended one more timeout after the abort (a task body that
  /// never returns) prints the report and ends the process with exit status 1.
  Watchdog(std::int64_t timeout_ms, std::function<std::uint64_t()> progress,
           std::function<std::string()> report, std::function<void(std::exception_ptr)> abort,
           bool exit_if_stuck);
  ~Watchdog();
  Watchdog(const Watchdog&) = delete;
  Watchdog& operator=(const Watchdog&) = delete;

  /// Step `seq` (> 0) starts: its context is published to the watchdog.
  void begin_step(std::uint64_t seq) {
    // release: the step context written before is visible to the watchdog's acquire.
    active_.store(seq, std::memory_order_release);
  }
  /// The step ended: the watchdog no longer touches its context. Never concurrent with an
  /// abort in progress (the abort runs under the same mutex).
  void end_step() {
    std::lock_guard<std::mutex> lock(mutex_);
    // relaxed: written and read under mutex_ where it matters (the abort decision).
    active_.store(0, std::memory_order_relaxed);
  }

 private:
  void watch();

  std::int64_t timeout_ms_;
  std::function<std::uint64_t()> progress_;
  std::function<std::string()> report_;
  std::function<void(std::exception_ptr)> abort_;
  bool exit_if_stuck_;
  std::mutex mutex_;
  std::condition_variable stop_cv_;
  bool stop_ = false;  // under mutex_
  std::atomic<std::uint64_t> active_{0};
  std::thread thread_;
};

}  // namespace tgraph::replay::detail
