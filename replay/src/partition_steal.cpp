// SPDX-License-Identifier: MIT
// The partitioned executor's partition-guided stealing (partition_runtime.hpp): a thread that
// would wait runs ready tasks of the programs, its own first, then the most loaded processor's.
#include <algorithm>
#include <functional>
#include <vector>

#include "partition_runtime.hpp"

namespace tgraph::replay::detail {

bool PartitionExecutor::try_steal(std::uint32_t self, ThreadCounters& tc) {
  // relaxed: a hint; a task a late reader runs was ready (the re-check below).
  if (abort_.load(std::memory_order_relaxed)) return false;
  const PartitionPlan& plan = *plan_;
  const std::uint32_t k = threads();
  const std::uint64_t E = epoch_;
  auto& order = thieves_[self].order;
  order.clear();
  for (std::uint32_t q = 0; q < k; ++q) {
    const std::uint32_t n_ops = static_cast<std::uint32_t>(plan.procs[q].ops.size());
    const std::uint32_t pc = cursor_of(q, E);
    if (pc >= n_ops) continue;
    order.emplace_back(q == self ? UINT32_MAX : n_ops - pc, q);
  }
  std::sort(order.begin(), order.end(), std::greater<>());
  for (const auto& [left, q] : order) {
    const std::vector<Op>& ops = plan.procs[q].ops;
    std::uint32_t seen = 0;
    for (std::size_t i = cursor_of(q, E); i < ops.size() && seen < kStealWindow; ++i) {
      const Op& op = ops[i];
      if (op.kind == OpKind::kLoopEnd) break;  // the next iteration: not before the decision
      if (op.kind != OpKind::kTask) continue;
      ++seen;
      if (plan.stealable[op.task] != 0 && steal_one(op, q, self, E, tc)) return true;
    }
  }
  return false;
}

bool PartitionExecutor::steal_one(const Op& op, std::uint32_t q, std::uint32_t self,
                                  std::uint64_t E, ThreadCounters& tc) {
  const PartitionPlan& plan = *plan_;
  const TaskId t = op.task;
  TaskState& st = state_[t];
  // relaxed: as in claim_own().
  std::uint64_t c = st.claim.load(std::memory_order_relaxed);
  const auto n = static_cast<std::uint32_t>(c >= E ? c - E : 0);  // executions claimed
  if (op.loop == kNoLoop) {
    if (n > 0) return false;
  } else if (n > 0) {
    // Iteration n exists: the loop's decision after iteration n - 1 is to go on.
    // acquire: pairs with the break task's signal (nothing read depends on it but the
    // decision; kept acquire as every other reader of loop counters).
    const std::uint64_t d = loop_[op.loop].v.load(std::memory_order_acquire);
    const auto decided = static_cast<std::uint32_t>((d & 0xffffffffu) >> 1);
    if ((d >> 32) != (E >> 32) || decided < n || (decided == n && (d & 1u) != 0)) return false;
    // The previous execution finished (executions of one task run in order).
    // acquire: its writes are visible to this one.
    if (st.fin.load(std::memory_order_acquire) < E + n) return false;
  }
  for (auto i = plan.steal_begin[t]; i < plan.steal_begin[t + 1]; ++i) {
    const WaitPoint& wp = plan.steal_waits[i];
    std::uint32_t loop_ran = 0;
    if (wp.kind == WaitKind::kAfterLoop) {
      // acquire: as above.
      const std::uint64_t d = loop_[wp.loop].v.load(std::memory_order_acquire);
      if ((d >> 32) != (E >> 32) || (d & 1u) == 0) return false;
      loop_ran = static_cast<std::uint32_t>((d & 0xffffffffu) >> 1);
    }
    const std::uint32_t need = detail::needed_executions(wp, n, loop_ran);
    // acquire: the producer's writes are visible to the task.
    if (need != 0 && state_[wp.producer].fin.load(std::memory_order_acquire) < E + need)
      return false;
  }
  // relaxed: a value poked by an abort was read with acquire above, after which the
  // abort flag (set before the poke) is seen.
  if (abort_.load(std::memory_order_relaxed)) return false;
  // relaxed: as in claim_own().
  if (!st.claim.compare_exchange_strong(c, E + n + 1, std::memory_order_relaxed)) return false;
  const bool observe = !observers().empty() && detail::sampled(n, observe_stride());
  if (observe) detail::notify_begin(observers(), self, t, n);
  Slot& slot = counters_[self];
  const bool watch = watchdog_ != nullptr;
  // relaxed: a report (a body that never returns is named as run here, inside the wait
  // whose task at_task keeps).
  if (watch) {
    slot.inside_of.store(q, std::memory_order_relaxed);
    slot.inside.store(t, std::memory_order_relaxed);
  }
  workload_->run(TaskRun{exec_, t, op.origin, n, self});
  if (watch) slot.inside.store(kNoTask, std::memory_order_relaxed);  // relaxed: as above
  if (observe) detail::notify_end(observers(), self, t, n);
  if (watch)  // relaxed: compared between two samples of the watchdog only
    slot.progress.store(slot.progress.load(std::memory_order_relaxed) + 1,
                        std::memory_order_relaxed);
  // A release (and a wake-up of the owner if it sleeps waiting for it).
  parking_.signal(st.fin, E + n + 1);
  ++tc.tasks;
  if (q != self) ++tc.stolen;
  return true;
}

void PartitionExecutor::finish_program(std::uint32_t p, ThreadCounters& tc) {
  // seq_cst RMW (a release): Dekker with the parked waiters as signal() (sync.hpp).
  programs_.fetch_add(1, std::memory_order_seq_cst);
  if (parking_.parked() != 0) parking_.wake(programs_);
  const std::uint64_t all = programs_target_;
  std::uint64_t v = 0;
  try {
    wait(
        programs_, [all](std::uint64_t s) { return s >= all; }, p, kNoTask, tc, v, 5, 0);
  } catch (...) {
    fail(std::current_exception());
  }
}

}  // namespace tgraph::replay::detail
