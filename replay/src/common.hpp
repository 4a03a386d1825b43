// SPDX-License-Identifier: MIT
// Internal helpers shared by the executors.
#pragma once

#include <cstdint>
#include <memory>
#include <vector>

#include "tgraph/replay/executor.hpp"

namespace tgraph::replay::detail {

/// Hard cap on the iterations of one loop (a live condition that never holds).
inline constexpr std::uint32_t kIterationCap = 1u << 16;

/// After iteration `i` of loop `l`: leave it? (the workload's condition, or the loop's
/// maximum, or the hard cap).
inline bool leave_loop(const ExecGraph& x, LoopId l, std::uint32_t i, Workload& w) {
  const bool stop = w.stop_after(l, i);
  const Loop& loop = x.graph.loops[l];
  return stop || (loop.max_iterations != 0 && i + 1 >= loop.max_iterations) ||
         i + 1 >= kIterationCap;
}

/// Iterations an unrolled loop runs when the workload knows `known` in advance: at least
/// one, at most the loop's maximum and the hard cap.
inline std::uint32_t unrolled_count(const Loop& loop, std::uint32_t known) {
  std::uint32_t count = known < 1 ? 1 : known;
  if (loop.max_iterations != 0 && loop.max_iterations < count) count = loop.max_iterations;
  return count < kIterationCap ? count : kIterationCap;
}

/// An unrolled loop's break task, iteration `i` of `count`: evaluates the condition (still
/// the workload's, which must agree with its known_iterations) and throws UsageError when
/// it disagrees. Returns the condition.
bool check_unrolled(const ExecGraph& x, LoopId l, std::uint32_t i, std::uint32_t count,
                    Workload& w);

/// Per-thread counters of a step, each thread's on its own cache line.
class ThreadSlots {
 public:
  explicit ThreadSlots(std::uint32_t threads)
      : slots_(std::make_unique<Slot[]>(threads)), threads_(threads) {}
  /// Thread p's counters (written by thread p only during a step).
  ThreadCounters& operator[](std::uint32_t p) { return slots_[p].c; }
  /// Zeroes every thread's counters (before a step).
  void reset() {
    for (std::uint32_t p = 0; p < threads_; ++p) slots_[p].c = {};
  }
  /// Copies them into `stats.threads` (after a step, the threads joined).
  void copy_to(ExecStepStats& stats) const {
    stats.threads.resize(threads_);
    for (std::uint32_t p = 0; p < threads_; ++p) stats.threads[p] = slots_[p].c;
  }

 private:
  struct alignas(64) Slot {
    ThreadCounters c;
  };
  std::unique_ptr<Slot[]> slots_;
  std::uint32_t threads_;
};

/// Before the first step of a plan: the calling thread first-touches every datum the
/// workload wants touched (the policies without data affinity).
inline void touch_all(const StepGraph& g, Workload& w) {
  for (DatumId d = 0; d < g.data.size(); ++d)
    if (w.needs_touch(d)) w.first_touch(d);
}

/// Walks step `g` in program order for the executors that submit or run it from one thread:
/// `task(t)` for each task outside loops, `loop(l)` once for each loop (at its first task;
/// the loop's body is then skipped). Stops before the next task or loop once `stop()`.
template <class Stop, class TaskFn, class LoopFn>
void walk_step(const StepGraph& g, Stop stop, TaskFn task, LoopFn loop) {
  const auto n = static_cast<TaskId>(g.tasks.size());
  std::size_t next_loop = 0;
  for (TaskId t = 0; t < n;) {
    if (stop()) return;
    if (next_loop < g.loops.size() && g.loops[next_loop].first == t) {
      const auto l = static_cast<LoopId>(next_loop++);
      loop(l);
      t = g.loops[l].last;
      continue;
    }
    task(t);
    ++t;
  }
}

/// Whether observers see loop iteration `it` under Executor::set_observe_stride(stride):
/// iterations 0 and 1 and every stride-th one (every instance outside loops).
inline bool sampled(std::uint32_t it, std::uint32_t stride) { return it < 2 || it % stride == 0; }

/// Calls every observer's on_begin.
inline void notify_begin(const std::vector<Observer*>& obs, std::uint32_t thread, TaskId t,
                         std::uint32_t it) {
  const std::int64_t now = now_ns();
  for (Observer* o : obs) o->on_begin(thread, t, it, now);
}
/// Calls every observer's on_end.
inline void notify_end(const std::vector<Observer*>& obs, std::uint32_t thread, TaskId t,
                       std::uint32_t it) {
  const std::int64_t now = now_ns();
  for (Observer* o : obs) o->on_end(thread, t, it, now);
}

/// Predecessor lists in CSR form.
struct Csr {
  std::vector<std::uint32_t> begin;
  std::vector<TaskId> ids;
  std::uint32_t size(TaskId t) const { return begin[t + 1] - begin[t]; }
};
/// Predecessors (by_to = true) or successors of every task along `edges`, deduplicated.
Csr build_csr(std::size_t n, const std::vector<Edge>& edges, bool by_to);

/// First-touch owner of each datum: the processor of the first task (program order)
/// accessing it; 0 for data no task touches.
std::vector<std::uint32_t> first_accessor_owner(const ExecGraph& x);

}  // namespace tgraph::replay::detail
