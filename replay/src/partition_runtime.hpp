// SPDX-License-Identifier: MIT
// The partitioned executor's threaded runtime (paper section 3.2), in three files:
// partition_executor.cpp (steps, workers, failures, the watchdog), partition_walk.cpp (a
// thread's walk through its program) and partition_steal.cpp (partition-guided stealing).
//
// One pinned thread per processor runs its own tasks in order (its program:
// partition_plan.hpp); a task needed by another processor publishes its completion count
// (signal) and the reader waits for it (spin, then park).
//
// Synchronisation: every task that another processor depends on owns a completion counter
// done[t] = (epoch << 32) | executions-this-step, so counters never need resetting between
// steps (the epoch grows). A datum's version is the completion count of its writer: the
// edges of the dataflow graph name, for each reader, exactly which writer (and for a CW
// group, which writers) produced the version it needs; WAR edges make a writer wait for the
// readers of the previous version the same way. Loops: every processor holding body tasks
// runs the loop control itself; the processor of the break task publishes, per iteration,
// loop[l] = (epoch << 32) | (iterations << 1) | stop, and the others read it before starting
// the next iteration. Combines (partition_plan.hpp, PartitionOptions::combine): each party
// adds one to arrivals[c] (acq_rel; reset to the epoch at the start of a step), and the one
// whose arrival completes an execution's count runs the reducer and the tasks after it, then
// publishes their done counters; the reducer's own processor, when not last, waits for
// combined[c] = epoch | executions instead. Calling thread = processor 0.
//
// Stealing (PartitionOptions::steal; partition_plan.hpp add_steal()): every task instance
// is claimed before it runs, by a compare-and-swap of claim[t] = epoch + executions claimed
// from its previous value, by its owner (at its place in the program) or by a thief (a
// thread that would otherwise wait, in block(), or that finished its program and waits for
// the others): exactly one of them runs it. Whoever ran it publishes fin[t] = epoch +
// executions finished; a thief runs an instance only when every execution its full
// dependency list names is finished (fin), the iteration exists (the loop's decision) and
// the task's previous execution is finished. The owner, reaching a task a thief took,
// passes its plan's waits as if it ran it, then waits for fin and publishes done[t] itself:
// done counters still follow program order, which the elided waits rely on. A stolen task
// writes the same temporaries (the lowering named them) and, through the CW chain in its
// dependencies, adds into each in its processor's order: the bits do not change.
#pragma once

#include <atomic>
#include <cstdint>
#include <exception>
#include <memory>
#include <mutex>
#include <string>
#include <thread>
#include <utility>
#include <vector>

#include "common.hpp"
#include "partition_plan.hpp"
#include "partition_testing.hpp"
#include "planned_executor.hpp"
#include "sync.hpp"
#include "tgraph/replay/executor.hpp"
#include "watchdog.hpp"

namespace tgraph::replay::detail {

class PartitionExecutor final : public detail::PlannedExecutor<PartitionPlan> {
 public:
  PartitionExecutor(const ExecOptions& o, const detail::PartitionTestHooks& hooks)
      : PlannedExecutor(Policy::kPartition, o),
        hooks_(hooks),
        parking_(o.spin_ns, o.threads > detail::hardware_pus()) {
    counters_ = std::make_unique<Slot[]>(o.threads);
  }

  std::uint64_t order_fallbacks() const override { return order_fallbacks_; }

  ~PartitionExecutor() override {
    watchdog_.reset();
    if (!workers_.empty()) {
      // relaxed: published by the seq_cst store of step_seq_ just below (a release); the
      // workers read shutdown_ after acquiring that value.
      shutdown_.store(true, std::memory_order_relaxed);
      // relaxed: only this thread writes step_seq_.
      parking_.signal(step_seq_, step_seq_.load(std::memory_order_relaxed) + 1);
      parking_.wake(step_seq_);
      for (auto& t : workers_) t.join();
    }
  }

 private:
  struct alignas(64) Slot {
    ThreadCounters c;
    // For the watchdog (relaxed: diagnostics; only the owning thread writes them).
    std::atomic<std::uint64_t> progress{0};       // tasks finished + blocked waits passed
    std::atomic<std::uint32_t> at_task{kNoTask};  // the task run or waited for last
    std::atomic<std::uint32_t> wait_kind{0};      // 0: none, 1: task, 2: loop, 3: first touch
    std::atomic<std::uint32_t> wait_id{0};        // the producer task or the loop
    // The task it runs inside a wait (stealing), kNoTask otherwise, and whose program it is.
    std::atomic<std::uint32_t> inside{kNoTask};
    std::atomic<std::uint32_t> inside_of{0};
    // Stealing: (step << 32) | the op the owner is at (relaxed: a hint where thieves look).
    std::atomic<std::uint64_t> cursor{0};
    // 1 while the thread sleeps in a wait (relaxed: a hint for the waiters of its counters,
    // which spin on while it runs).
    std::atomic<std::uint32_t> sleeping{0};
  };

  // Stealing: one task's claim and completion counters (epoch + executions), on one line.
  struct alignas(64) TaskState {
    std::atomic<std::uint64_t> claim{0};
    std::atomic<std::uint64_t> fin{0};
  };

  // A thief's scratch: the processors to look at, most ops left first.
  struct Thief {
    std::vector<std::pair<std::uint32_t, std::uint32_t>> order;  // (ops left, processor)
  };

  std::unique_ptr<PartitionPlan> build_plan(const ExecGraph& x) override {
    return checked(x, detail::build_plan(x, threads(), true, options().partition.elide_waits));
  }

  std::unique_ptr<PartitionPlan> update_plan(const ExecGraph& x,
                                             const PartitionPlan& previous) override {
    return checked(
        x, detail::update_plan(x, previous, threads(), true, options().partition.elide_waits));
  }

  std::uint32_t rebuilt(const PartitionPlan& plan) const override { return plan.rebuilt_procs; }

  // Program order on every processor never deadlocks (every wait names an earlier task in
  // program order); only an explicit order needs the check. Then the combines are marked
  // (they add no wait a deadlock could come from: a combine runs once its parties arrive,
  // which the plan's own waits already required). PartitionTestHooks::lose_signal is
  // applied last, to full and incremental builds alike.
  std::unique_ptr<PartitionPlan> checked(const ExecGraph& x, PartitionPlan built);

  void run(PartitionPlan& plan, const ExecGraph& x, Workload& w, bool fresh,
           ExecStepStats& stats) override;
  void start_workers();
  void worker(std::uint32_t p);
  // Records the first failure and aborts the step: every waiter wakes and leaves.
  void fail(std::exception_ptr e);

  // Arrival at combine c in the step of epoch E: whether the caller is the last of its
  // parties in this execution (then it runs the combine).
  bool arrive(std::uint32_t c, std::uint64_t E, std::uint32_t parties) {
    // acq_rel: releases what the caller ran (and acquired) to the last to arrive, which
    // acquires every party's through the chain of these read-modify-writes.
    const std::uint64_t before = arrivals_[c].v.fetch_add(1, std::memory_order_acq_rel);
    return (before - E + 1) % parties == 0;
  }

  // Waits until ok(c); false when the step is aborting. The check that holds at once is
  // inlined into the hot loop; blocking is out of line (block()).
  // `kind`/`id`: what is waited for, for the watchdog's report (1: task id's completion,
  // 2: loop id's decision, 3: the first-touch barrier, 4: combine id).
  template <class Ok>
  bool wait(std::atomic<std::uint64_t>& c, Ok ok, std::uint32_t thread, TaskId task,
            ThreadCounters& tc, std::uint64_t& value, std::uint32_t kind, std::uint32_t id) {
    ++tc.waits;
    // acquire: pairs with the signaller's store; its writes are visible to our task.
    value = c.load(std::memory_order_acquire);
    if (!ok(value)) [[unlikely]]
      value = block(c, ok, thread, task, tc, kind, id);
    // relaxed: a hint; when set, no task runs after this point, so nothing depends on it.
    return !abort_.load(std::memory_order_relaxed);
  }

  // The blocking part of wait(): spin, then park; returns the value that satisfied ok (or
  // the last one read when aborting).
  template <class Ok>
  [[gnu::noinline]] std::uint64_t block(std::atomic<std::uint64_t>& c, Ok ok, std::uint32_t thread,
                                        TaskId task, ThreadCounters& tc, std::uint32_t kind,
                                        std::uint32_t id) {
    Slot& slot = counters_[thread];
    // relaxed: read by the watchdog for its report only.
    slot.at_task.store(task, std::memory_order_relaxed);
    slot.wait_id.store(id, std::memory_order_relaxed);
    slot.wait_kind.store(kind, std::memory_order_relaxed);
    bool parked = false;
    std::int64_t waited = 0;
    const std::int64_t t0 = observers().empty() ? 0 : now_ns();
    // The thread whose signal ends the wait, where one does: the producer's processor (a
    // task's completion), the break task's (a loop's decision). The wait spins on while it
    // runs (Parking::wait). A stolen task's thief runs it now, and the end of the programs
    // waits for threads that run: those spin on too; a combine's parties are not known.
    constexpr std::uint32_t kNone = UINT32_MAX, kRunning = UINT32_MAX - 1;
    std::uint32_t from = kind == 5 || kind == 6 ? kRunning : kNone;
    if (kind == 1 && id < plan_->proc.size()) from = plan_->proc[id];
    if (kind == 2 && id < plan_->breaks.size()) from = plan_->proc[plan_->breaks[id]];
    const auto awake = [this, from] {
      if (from >= kRunning) return from == kRunning;
      // relaxed: a hint (spin or park); the counter decides.
      return counters_[from].sleeping.load(std::memory_order_relaxed) == 0;
    };
    // While it waits, the thread runs ready tasks (not at the first-touch barrier: data
    // may not exist yet).
    const std::uint64_t value =
        steal_ && kind != 3
            ? parking_.wait(
                  c, ok, abort_, parked, waited,
                  [&] { return try_steal(thread, tc); },
                  awake, &slot.sleeping)
            : parking_.wait(
                  c, ok, abort_, parked, waited, [] { return false; }, awake, &slot.sleeping);
    // relaxed: as above; progress is only compared between two samples.
    slot.wait_kind.store(0, std::memory_order_relaxed);
    slot.progress.store(slot.progress.load(std::memory_order_relaxed) + 1,
                        std::memory_order_relaxed);
    ++tc.blocked_waits;
    tc.parks += parked ? 1 : 0;
    tc.wait_ns += waited;
    if (!observers().empty())
      for (Observer* o : observers()) o->on_wait(thread, task, t0, t0 + waited, parked);
    return value;
  }

  // Owner's claim of its task t's execution `iter` (its place in its program): false when
  // a thief claimed it first.
  bool claim_own(TaskId t, std::uint64_t E, std::uint32_t iter) {
    std::atomic<std::uint64_t>& claim = state_[t].claim;
    const std::uint64_t want = E + iter + 1;
    // relaxed: the claim only decides who runs the instance; the data a task needs come
    // through fin (acquire) and the plan's waits.
    std::uint64_t c = claim.load(std::memory_order_relaxed);
    if (c >= want) return false;
    // relaxed: as above; a failed exchange means a thief claimed it (c >= want then).
    return claim.compare_exchange_strong(c, want, std::memory_order_relaxed);
  }

  // Ops of a processor's program a thief looks at, from where its owner is.
  static constexpr std::uint32_t kStealWindow = 32;

  // Runs one ready task of some program (the thread's own ahead of its place first, then
  // those of the processors with the most ops left) as thread `self`; false when none is
  // ready. Only where steal_.
  bool try_steal(std::uint32_t self, ThreadCounters& tc);

  // Where the owner of program q is this step (0: not started).
  std::uint32_t cursor_of(std::uint32_t q, std::uint64_t E) const {
    // relaxed: a hint where to look; claims and fin decide.
    const std::uint64_t c = counters_[q].cursor.load(std::memory_order_relaxed);
    return (c >> 32) == (E >> 32) ? static_cast<std::uint32_t>(c) : 0;
  }

  // Runs the next unclaimed execution of `op` (of processor q's program) on thread `self`
  // if it is ready; false if it is not, or claimed.
  bool steal_one(const Op& op, std::uint32_t q, std::uint32_t self, std::uint64_t E,
                 ThreadCounters& tc);

  // PartitionTestHooks::lose_signal: the task's completion is never published.
  void lose_signal(PartitionPlan& plan, const ExecGraph& x) const;
  void start_watchdog();
  // Where each thread stands (the watchdog's report; the step context is valid).
  std::string stall_report() const;

  // A counter to prefetch, and whether for writing (an arrival's read-modify-write).
  struct Prefetch {
    const void* at = nullptr;
    bool write = false;
  };

  // The counter the op after a plain run checks first (its first wait's producer, or its
  // loop's decision), or, for a combine's head or offer, the arrival counter it adds to;
  // none when it checks none here.
  Prefetch next_check(const Op* ops, std::size_t next, std::size_t n_ops,
                      const WaitPoint* waits) const {
    if (next >= n_ops) return {};
    const Op& op = ops[next];
    if (op.kind == OpKind::kLoopEnd) return {&loop_[op.loop].v};
    if (op.kind != OpKind::kTask) return {};
    if (op.combine != CombineRole::kNone) return {&arrivals_[op.jump].v, true};
    if (op.wait_begin == op.wait_end) return {};
    const WaitPoint& wp = waits[op.wait_begin];
    return {wp.kind == WaitKind::kAfterLoop ? &loop_[wp.loop].v : &done_[wp.producer].v};
  }

  // Tasks before the end of a plain run at which run_plain prefetches the next op's counter.
  static constexpr std::size_t kPrefetchAhead = 8;

  // Runs the ops[pc].plain_run ops from ops[pc] on (tasks that neither wait nor publish); returns
  // the first op past them. With `Watch`, the slot tells the watchdog what runs and that the
  // thread progresses. Out of line, so that what the loop keeps across the body's call stays
  // in registers (inlined into run_proc, it reloaded the workload, the graph and the bounds
  // from the stack at every task); the TaskRun is built once, each task setting its two ids.
  // `next`: the counter the op after the run checks first; it is prefetched kPrefetchAhead
  // tasks before the end (half way in a shorter run), so that a value its producer published
  // while this thread ran is already in this core's cache when the check reads it: a miss
  // less on the critical path of a hand-off (a loop decision read at the end of the body, a
  // producer that ran ahead). An arrival counter is prefetched for writing: the party
  // arriving last then finds it in this core's cache, the others having added to it.
  template <bool Watch>
  [[gnu::noinline]] static std::size_t run_plain(const Op* ops, std::size_t pc, const ExecGraph& x,
                                                 Workload& w, std::uint32_t iter, std::uint32_t p,
                                                 Slot& slot, Prefetch next);

  // Thread p's walk through its program for the step (partition_walk.cpp).
  void run_proc(std::uint32_t p);

  // The owner's wait for its task t's execution `iter`, which a thief claimed; false when
  // the step is aborting.
  bool await_stolen(TaskId t, std::uint64_t E, std::uint32_t iter, std::uint32_t p,
                    ThreadCounters& tc) {
    const std::uint64_t target = E + iter + 1;
    std::uint64_t v = 0;
    return wait(
        state_[t].fin, [target](std::uint64_t s) { return s >= target; }, p, t, tc, v, 6, t);
  }

  // Stealing: the end of thread p's own program. Until every program has ended, it runs
  // ready tasks of the others (spinning, then parking when none comes).
  void finish_program(std::uint32_t p, ThreadCounters& tc);

  detail::PartitionTestHooks hooks_;
  detail::Parking parking_;
  std::vector<std::thread> workers_;
  bool started_ = false;
  detail::MainThreadBinding main_binding_;
  std::unique_ptr<Slot[]> counters_;
  std::unique_ptr<PaddedCounter[]> done_;
  std::size_t done_cap_ = 0;
  std::unique_ptr<PaddedCounter[]> loop_;
  std::size_t loop_cap_ = 0;
  std::unique_ptr<PaddedCounter[]> arrivals_;  // by combine: epoch + arrivals this step
  std::unique_ptr<PaddedCounter[]> combined_;  // by combine: epoch | executions run
  std::size_t combine_cap_ = 0;
  std::unique_ptr<TaskState[]> state_;  // stealing: by task
  std::size_t state_cap_ = 0;
  std::unique_ptr<Thief[]> thieves_;  // by thread
  // Step context: written by the main thread before the step_seq_ store, read by workers
  // after acquiring it.
  const PartitionPlan* plan_ = nullptr;
  const ExecGraph* exec_ = nullptr;
  Workload* workload_ = nullptr;
  bool fresh_ = false;
  bool steal_ = false;                 // this step steals
  std::uint64_t programs_target_ = 0;  // programs_ once every program of this step ended
  std::uint64_t epoch_ = 0;
  std::uint64_t steps_ = 0;
  alignas(64) std::atomic<std::uint64_t> step_seq_{0};
  alignas(64) std::atomic<std::uint64_t> finished_{0};
  alignas(64) std::atomic<std::uint64_t> touched_{0};   // first-touch barrier arrivals
  alignas(64) std::atomic<std::uint64_t> programs_{0};  // stealing: programs ended, all steps
  std::uint64_t touch_rounds_ = 0;
  std::uint64_t order_fallbacks_ = 0;
  alignas(64) std::atomic<bool> abort_{false};
  std::atomic<bool> shutdown_{false};
  const std::atomic<bool> never_abort_{false};
  std::mutex error_mutex_;
  std::exception_ptr error_;
  std::unique_ptr<detail::Watchdog> watchdog_;  // last member: stopped first
};

}  // namespace tgraph::replay::detail
