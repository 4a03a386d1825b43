// SPDX-License-Identifier: MIT
// The replay watchdog (watchdog.hpp).
#include "watchdog.hpp"

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <stdexcept>

namespace tgraph::replay::detail {

Watchdog::Watchdog(std::int64_t timeout_ms, std::function<std::uint64_t()> progress,
                   std::function<std::string()> report,
                   std::function<void(std::exception_ptr)> abort, bool exit_if_stuck)
    : timeout_ms_(timeout_ms),
      progress_(std::move(progress)),
      report_(std::move(report)),
      abort_(std::move(abort)),
      exit_if_stuck_(exit_if_stuck) {
  thread_ = std::thread([this] { watch(); });
}

Watchdog::~Watchdog() {
  {
    std::lock_guard<std::mutex> lock(mutex_);
    stop_ = true;
  }
  stop_cv_.notify_all();
  thread_.join();
}

void Watchdog::watch() {
  using Clock = std::chrono::steady_clock;
  const auto timeout = std::chrono::milliseconds(timeout_ms_);
  // Four samples per timeout (at most one a second): a stall is caught within 1.25 x the
  // timeout, and an idle executor costs a few wake-ups a second at most.
  const auto period =
      std::clamp(timeout / 4, std::chrono::milliseconds(1), std::chrono::milliseconds(1000));
  std::uint64_t last_step = 0, last_progress = 0, fired_step = 0;
  auto since = Clock::now();
  std::unique_lock<std::mutex> lock(mutex_);
  for (;;) {
    if (stop_cv_.wait_for(lock, period, [this] { return stop_; })) return;
    // acquire: pairs with begin_step(); the step context is visible to report_ and abort_.
    const std::uint64_t step = active_.load(std::memory_order_acquire);
    const std::uint64_t progress = step != 0 ? progress_() : 0;
    const auto now = Clock::now();
    if (step == 0 || step != last_step || progress != last_progress) {
      last_step = step;
      last_progress = progress;
      since = now;
      continue;
    }
    if (now - since < timeout) continue;
    const double seconds = std::chrono::duration<double>(now - since).count();
    if (fired_step != step) {
      // Under mutex_: end_step() waits, so the step (and its context) outlives the abort.
      fired_step = step;
      char head[96];
      std::snprintf(head, sizeof head,
                    "replay stopped making progress for %.1f s (watchdog timeout): ", seconds);
      abort_(std::make_exception_ptr(std::runtime_error(head + report_())));
      since = now;
    } else if (exit_if_stuck_) {
      // The abort woke every wait; a thread still inside a task body cannot be interrupted.
      std::fprintf(stderr,
                   "tgraph: replay stopped making progress (watchdog timeout): %s; a task body "
                   "does not return, ending the process\n",
                   report_().c_str());
      std::fflush(stderr);
      std::_Exit(1);
    }
  }
}

}  // namespace tgraph::replay::detail
