// SPDX-License-Identifier: MIT
// The partitioned executor's walk of one thread through its program for a step
// (partition_runtime.hpp): plain runs of tasks, waits, signals, loops and combines.
#include <exception>

#include "partition_runtime.hpp"

namespace tgraph::replay::detail {

template <bool Watch>
std::size_t PartitionExecutor::run_plain(const Op* ops, std::size_t pc, const ExecGraph& x,
                                         Workload& w, std::uint32_t iter, std::uint32_t p,
                                         Slot& slot, Prefetch next) {
  const std::uint32_t n = ops[pc].plain_run;
  const std::size_t end = pc + n;
  TaskRun run{&x, 0, kNoTask, iter, p};
  const std::size_t fetch_at =
      next.at == nullptr ? end : (n > 2 * kPrefetchAhead ? end - kPrefetchAhead : pc + n / 2);
  for (; pc < end; ++pc) {
    if (pc == fetch_at) {
      if (next.write)
        __builtin_prefetch(next.at, 1, 3);
      else
        __builtin_prefetch(next.at, 0, 3);
    }
    const Op& op = ops[pc];
    if constexpr (Watch) slot.at_task.store(op.task, std::memory_order_relaxed);  // a report
    run.task = op.task;
    run.origin = op.origin;
    w.run(run);
  }
  if constexpr (Watch)  // relaxed: compared between two samples of the watchdog only
    slot.progress.store(slot.progress.load(std::memory_order_relaxed) + n,
                        std::memory_order_relaxed);
  return pc;
}

void PartitionExecutor::run_proc(std::uint32_t p) {
  ThreadCounters tc{};
  const PartitionPlan& plan = *plan_;
  const ExecGraph& x = *exec_;
  Workload& w = *workload_;
  const ProcPlan& pp = plan.procs[p];
  const std::uint64_t E = epoch_;
  const bool observe = !observers().empty();
  const std::uint32_t stride = observe_stride();
  const bool watch = watchdog_ != nullptr;
  const bool steal = steal_;
  Slot& slot = counters_[p];
  // Kept in registers in the loop (tc escapes into wait()), added to tc at the end.
  std::uint64_t tasks = 0, signals = 0;
  try {
    if (fresh_) {
      // A failed allocation still arrives at the barrier below (the others would wait
      // for it forever otherwise) and then leaves with the step aborted.
      try {
        for (DatumId d : pp.owned)
          if (w.needs_touch(d)) w.first_touch(d);
      } catch (...) {
        fail(std::current_exception());
      }
      // Every buffer exists before any task runs: a barrier over the k threads.
      // seq_cst RMW (a release): our allocations reach the threads acquiring the total.
      touched_.fetch_add(1, std::memory_order_seq_cst);
      if (parking_.parked() != 0) parking_.wake(touched_);
      const std::uint64_t all = touch_rounds_ * options().threads;
      std::uint64_t seen = 0;
      if (!wait(
              touched_, [all](std::uint64_t s) { return s >= all; }, p, kNoTask, tc, seen, 3, 0))
        goto out;
    }
    std::uint32_t iter = 0;
    std::uint64_t v = 0;
    // Runs a task op (of this program, or of a combine's home) and publishes its completion.
    const auto execute = [&](const Op& op) {
      if (observe && detail::sampled(iter, stride))
        detail::notify_begin(observers(), p, op.task, iter);
      if (watch) slot.at_task.store(op.task, std::memory_order_relaxed);  // relaxed: report
      w.run(TaskRun{&x, op.task, op.origin, iter, p});
      if (observe && detail::sampled(iter, stride))
        detail::notify_end(observers(), p, op.task, iter);
      if (watch)  // relaxed: compared between two samples of the watchdog only
        slot.progress.store(slot.progress.load(std::memory_order_relaxed) + 1,
                            std::memory_order_relaxed);
      // release: a thief that reads it runs a successor (after the end observers saw;
      // nobody sleeps on it: only the owner of a stolen task does, and the thief
      // publishes that one).
      if (steal) state_[op.task].fin.store(E + iter + 1, std::memory_order_release);
      ++tasks;
      if (op.signal) {
        parking_.signal(done_[op.task].v, E + iter + 1);
        ++signals;
      }
    };
    const Op* const ops = pp.ops.data();
    const WaitPoint* const waits = pp.waits.data();
    const std::size_t n_ops = pp.ops.size();
    for (std::size_t pc = 0; pc < n_ops;) {
      const Op& op = ops[pc];
      // relaxed: a hint for thieves (where to look).
      if (steal) slot.cursor.store(E | pc, std::memory_order_relaxed);
      switch (op.kind) {
        case OpKind::kLoopBegin:
          iter = 0;
          ++pc;
          break;
        case OpKind::kLoopEnd: {
          const std::uint64_t need = E | (static_cast<std::uint64_t>(iter + 1) << 1);
          if (!wait(
                  loop_[op.loop].v, [need](std::uint64_t s) { return s >= need; }, p, kNoTask, tc,
                  v, 2, op.loop))
            goto out;
          const std::uint64_t decided = (v & 0xffffffffu) >> 1;
          if (decided > iter + 1 || (v & 1u) == 0) {
            ++iter;
            pc = op.jump;
          } else {
            iter = 0;
            ++pc;
          }
          break;
        }
        case OpKind::kTask: {
          if (steal && op.plain_run != 0 && op.combine == CombineRole::kNone) {
            // The plain run task by task: each claimed, or waited for if a thief took it.
            const std::size_t end = pc + op.plain_run;
            for (; pc < end; ++pc) {
              const Op& o = ops[pc];
              slot.cursor.store(E | pc, std::memory_order_relaxed);  // relaxed: as above
              if (!plan.stealable[o.task] || claim_own(o.task, E, iter)) {
                execute(o);
              } else if (!await_stolen(o.task, E, iter, p, tc)) {
                goto out;
              }
            }
            break;
          }
          if (!observe && op.plain_run != 0) {
            // A run of tasks that neither wait nor publish: the sequential loop.
            tasks += op.plain_run;
            const Prefetch next = next_check(ops, pc + op.plain_run, n_ops, waits);
            pc = watch ? run_plain<true>(ops, pc, x, w, iter, p, slot, next)
                       : run_plain<false>(ops, pc, x, w, iter, p, slot, next);
            break;
          }
          if (op.combine == CombineRole::kHead) [[unlikely]] {
            // Arrival instead of the waits (each producer arrives after running). Not
            // last: another party runs the combine; wait until it has.
            const detail::Combine& c = plan.combines[op.jump];
            if (!arrive(op.jump, E, c.parties)) {
              const std::uint64_t target = E + iter + 1;
              if (!wait(
                      combined_[op.jump].v, [target](std::uint64_t s) { return s >= target; }, p,
                      op.task, tc, v, 4, op.jump))
                goto out;
              pc = c.end;
              break;
            }
          }
          for (auto i = op.combine == CombineRole::kHead ? op.wait_end : op.wait_begin;
               i < op.wait_end; ++i) {
            const WaitPoint& wp = waits[i];
            std::uint32_t loop_ran = 0;
            if (wp.kind == WaitKind::kAfterLoop) {  // the loop's decision to stop first
              const std::uint64_t epoch = E;
              if (!wait(
                      loop_[wp.loop].v,
                      [epoch](std::uint64_t s) { return (s >> 32) == (epoch >> 32) && (s & 1u); },
                      p, op.task, tc, v, 2, wp.loop))
                goto out;
              loop_ran = static_cast<std::uint32_t>((v & 0xffffffffu) >> 1);
            }
            const std::uint32_t need = detail::needed_executions(wp, iter, loop_ran);
            if (need == 0) continue;
            const std::uint64_t target = E + need;
            if (!wait(
                    done_[wp.producer].v, [target](std::uint64_t s) { return s >= target; }, p,
                    op.task, tc, v, 1, wp.producer))
              goto out;
          }
          if (steal && plan.stealable[op.task] && !claim_own(op.task, E, iter)) {
            // A thief runs or ran it: its completion, then published here, in order.
            if (!await_stolen(op.task, E, iter, p, tc)) goto out;
            if (op.signal) {
              parking_.signal(done_[op.task].v, E + iter + 1);
              ++signals;
            }
            ++pc;
            break;
          }
          execute(op);
          if (op.is_break) {
            const bool stop = detail::leave_loop(x, op.loop, iter, w);
            parking_.signal(loop_[op.loop].v,
                            E | (static_cast<std::uint64_t>(iter + 1) << 1) | (stop ? 1u : 0u));
            ++signals;
          }
          if (op.combine == CombineRole::kOffer) [[unlikely]] {
            const detail::Combine& c = plan.combines[op.jump];
            if (arrive(op.jump, E, c.parties)) {  // last: the combine runs here
              const Op* const home = plan.procs[c.home].ops.data();
              for (std::uint32_t i = c.head; i < c.end; ++i) execute(home[i]);
              parking_.signal(combined_[op.jump].v, E + iter + 1);
              ++signals;
            }
          }
          ++pc;
          break;
        }
      }
    }
  } catch (...) {
    fail(std::current_exception());
  }
out:
  if (steal) finish_program(p, tc);
  tc.tasks += tasks;
  tc.signals += signals;
  counters_[p].c = tc;
}

}  // namespace tgraph::replay::detail
