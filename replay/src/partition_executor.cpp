// SPDX-License-Identifier: MIT
// The partitioned executor's threaded runtime (paper section 3.2): one pinned thread per
// processor runs its own tasks in order (its program: partition_plan.hpp); a task needed by
// another processor publishes its completion count (signal) and the reader waits for it
// (spin, then park).
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
#include <algorithm>
#include <atomic>
#include <exception>
#include <functional>
#include <memory>
#include <mutex>
#include <stdexcept>
#include <string>
#include <thread>
#include <utility>
#include <vector>

#include "common.hpp"
#include "partition_plan.hpp"
#include "partition_report.hpp"
#include "partition_serial.hpp"
#include "partition_testing.hpp"
#include "planned_executor.hpp"
#include "sync.hpp"
#include "tgraph/graph/error.hpp"
#include "tgraph/replay/executor.hpp"
#include "watchdog.hpp"

namespace tgraph::replay {
namespace {

using detail::CombineRole;
using detail::Op;
using detail::OpKind;
using detail::PaddedCounter;
using detail::PartitionPlan;
using detail::ProcPlan;
using detail::WaitKind;
using detail::WaitPoint;

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
  std::unique_ptr<PartitionPlan> checked(const ExecGraph& x, PartitionPlan built) {
    auto plan = std::make_unique<PartitionPlan>(std::move(built));
    if (!plan->program_order) {
      try {
        detail::check_deadlock_free(*plan, x);
      } catch (const UsageError&) {
        if (!x.added_edges) throw;  // the order itself is invalid
        // The explicit order cannot be kept with the lowered graph's extra edges (serialised
        // CW writers): fall back to program order on each processor, which never deadlocks.
        *plan = detail::build_plan(x, threads(), false, options().partition.elide_waits);
        ++order_fallbacks_;
      }
    }
    if (options().partition.combine && !options().partition.serial) detail::add_combines(x, *plan);
    if (options().partition.steal && !options().partition.serial && threads() > 1)
      detail::add_steal(x, *plan);
    lose_signal(*plan, x);
    return plan;
  }

  void run(PartitionPlan& plan, const ExecGraph& x, Workload& w, bool fresh,
           ExecStepStats& stats) override {
    const std::uint32_t k = threads();
    if (options().partition.serial) {
      if (fresh)
        for (const ProcPlan& pp : plan.procs)
          for (DatumId d : pp.owned)
            if (w.needs_touch(d)) w.first_touch(d);
      detail::run_interleaved(plan, x, &w, &observers(), &stats);
      return;
    }
    start_workers();
    if (plan.tasks > done_cap_) {
      done_ = std::make_unique<PaddedCounter[]>(plan.tasks);
      done_cap_ = plan.tasks;
    }
    if (plan.loops > loop_cap_) {
      loop_ = std::make_unique<PaddedCounter[]>(plan.loops);
      loop_cap_ = plan.loops;
    }
    if (plan.combines.size() > combine_cap_) {
      arrivals_ = std::make_unique<PaddedCounter[]>(plan.combines.size());
      combined_ = std::make_unique<PaddedCounter[]>(plan.combines.size());
      combine_cap_ = plan.combines.size();
    }
    steal_ = k > 1 && plan.stealable.size() == plan.tasks && plan.tasks > 0;
    if (steal_) {
      if (plan.tasks > state_cap_) {
        state_ = std::make_unique<TaskState[]>(plan.tasks);
        state_cap_ = plan.tasks;
      }
      if (!thieves_) thieves_ = std::make_unique<Thief[]>(k);
      programs_target_ += k;
    }
    plan_ = &plan;
    exec_ = &x;
    workload_ = &w;
    fresh_ = fresh;
    if (fresh) ++touch_rounds_;
    error_ = nullptr;
    // relaxed: published to the workers by the release in signal(step_seq_) below.
    abort_.store(false, std::memory_order_relaxed);
    const std::uint64_t seq = ++steps_;
    epoch_ = seq << 32;
    for (std::size_t c = 0; c < plan.combines.size(); ++c)
      arrivals_[c].v.store(epoch_, std::memory_order_relaxed);  // relaxed: as abort_ below
    start_watchdog();
    if (watchdog_) watchdog_->begin_step(seq);  // a release: step context visible
    parking_.signal(step_seq_, seq);            // seq_cst store (a release): step context visible
    run_proc(0);
    if (k > 1) {
      bool parked = false;
      std::int64_t waited = 0;
      const std::uint64_t target = seq * (k - 1);
      // acquire (inside wait): every worker's counters and writes are visible afterwards.
      parking_.wait(
          finished_, [target](std::uint64_t v) { return v >= target; }, never_abort_, parked,
          waited, [] { return false; }, [] { return false; }, &counters_[0].sleeping);
    }
    if (watchdog_) watchdog_->end_step();
    stats.threads.resize(k);
    for (std::uint32_t p = 0; p < k; ++p) stats.threads[p] = counters_[p].c;
    stats.loop_iterations.resize(plan.loops);
    for (std::size_t l = 0; l < plan.loops; ++l) {
      // relaxed: all writers finished (acquire on finished_ above).
      const std::uint64_t v = loop_[l].v.load(std::memory_order_relaxed);
      stats.loop_iterations[l] =
          (v >> 32) == seq ? static_cast<std::uint32_t>((v & 0xffffffffu) >> 1) : 0;
    }
    if (error_) std::rethrow_exception(error_);
  }

  void start_workers() {
    if (started_) return;
    started_ = true;
    if (options().pin) {
      main_binding_.save_once();  // restored when the executor is destroyed
      detail::pin_current_thread(0);
    }
    for (std::uint32_t p = 1; p < options().threads; ++p)
      workers_.emplace_back([this, p] { worker(p); });
  }

  void worker(std::uint32_t p) {
    if (options().pin) detail::pin_current_thread(p);
    std::uint64_t seen = 0;
    for (;;) {
      bool parked = false;
      std::int64_t waited = 0;
      // acquire (inside wait): the step context written before the store is visible.
      seen = parking_.wait(
          step_seq_, [seen](std::uint64_t v) { return v > seen; }, never_abort_, parked, waited,
          [] { return false; }, [] { return false; }, &counters_[p].sleeping);
      // relaxed: ordered by the acquire of step_seq_ above.
      if (shutdown_.load(std::memory_order_relaxed)) return;
      run_proc(p);
      // seq_cst RMW (a release): the counters and the task's writes reach the main thread.
      finished_.fetch_add(1, std::memory_order_seq_cst);
      if (parking_.parked() != 0) parking_.wake(finished_);
    }
  }

  void fail(std::exception_ptr e) {
    {
      std::lock_guard<std::mutex> lock(error_mutex_);
      if (!error_) error_ = e;
    }
    // seq_cst: Dekker with the waiters' abort check before they sleep (sync.hpp).
    if (abort_.exchange(true, std::memory_order_seq_cst)) return;
    // std::atomic::wait only promises to wake a sleeper whose value changed, so each
    // counter is bumped (within this epoch: below every later target) before the notify;
    // a woken waiter sees abort_ and leaves.
    for (std::size_t t = 0; t < plan_->tasks; ++t) parking_.poke(done_[t].v);
    for (std::size_t l = 0; l < plan_->loops; ++l) parking_.poke(loop_[l].v);
    for (std::size_t c = 0; c < plan_->combines.size(); ++c) parking_.poke(combined_[c].v);
    if (steal_)
      for (std::size_t t = 0; t < plan_->tasks; ++t) parking_.poke(state_[t].fin);
  }

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
                  [&] {
                    if (!try_steal(thread, tc)) return false;
                    // relaxed: as above.
                    slot.at_task.store(task, std::memory_order_relaxed);
                    return true;
                  },
                  awake, &slot.sleeping)
            : parking_.wait(c, ok, abort_, parked, waited, [] { return false; }, awake,
                            &slot.sleeping);
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
  bool try_steal(std::uint32_t self, ThreadCounters& tc) {
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

  // Where the owner of program q is this step (0: not started).
  std::uint32_t cursor_of(std::uint32_t q, std::uint64_t E) const {
    // relaxed: a hint where to look; claims and fin decide.
    const std::uint64_t c = counters_[q].cursor.load(std::memory_order_relaxed);
    return (c >> 32) == (E >> 32) ? static_cast<std::uint32_t>(c) : 0;
  }

  // Runs the next unclaimed execution of `op` (of processor q's program) on thread `self`
  // if it is ready; false if it is not, or claimed.
  bool steal_one(const Op& op, std::uint32_t q, std::uint32_t self, std::uint64_t E,
                 ThreadCounters& tc) {
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
    if (watch) slot.at_task.store(t, std::memory_order_relaxed);  // relaxed: a report
    workload_->run(TaskRun{exec_, t, op.origin, n, self});
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

  // PartitionTestHooks::lose_signal: the task's completion is never published.
  void lose_signal(PartitionPlan& plan, const ExecGraph& x) const {
    if (!hooks_.lose_signal || *hooks_.lose_signal >= x.exec_of.size()) return;
    const TaskId t = x.exec_of[*hooks_.lose_signal];
    for (ProcPlan& pp : plan.procs)
      for (Op& op : pp.ops)
        if (op.kind == OpKind::kTask && op.task == t) {
          op.signal = false;
          if (op.combine == CombineRole::kOffer) op.combine = CombineRole::kNone;  // no arrival
        }
  }

  void start_watchdog() {
    if (watchdog_ || options().partition.timeout_ms <= 0) return;
    watchdog_ = std::make_unique<detail::Watchdog>(
        options().partition.timeout_ms,
        [this] {
          std::uint64_t sum = 0;
          for (std::uint32_t p = 0; p < options().threads; ++p)
            sum += counters_[p].progress.load(std::memory_order_relaxed);  // relaxed: a sample
          return sum;
        },
        [this] { return stall_report(); }, [this](std::exception_ptr e) { fail(e); },
        options().partition.timeout_exits);
  }

  // Where each thread stands (the watchdog's report; the step context is valid).
  std::string stall_report() const {
    std::vector<detail::ThreadStand> threads(options().threads);
    for (std::uint32_t p = 0; p < threads.size(); ++p) {
      const Slot& s = counters_[p];
      // relaxed: diagnostics, a racy snapshot is fine.
      threads[p] = {s.wait_kind.load(std::memory_order_relaxed),
                    s.wait_id.load(std::memory_order_relaxed),
                    s.at_task.load(std::memory_order_relaxed)};
    }
    return detail::stall_report(*exec_, *plan_, threads);
  }

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

  void run_proc(std::uint32_t p) {
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

  // The owner's wait for its task t's execution `iter`, which a thief claimed; false when
  // the step is aborting.
  bool await_stolen(TaskId t, std::uint64_t E, std::uint32_t iter, std::uint32_t p,
                    ThreadCounters& tc) {
    const std::uint64_t target = E + iter + 1;
    std::uint64_t v = 0;
    return wait(state_[t].fin, [target](std::uint64_t s) { return s >= target; }, p, t, tc, v, 6,
                t);
  }

  // Stealing: the end of thread p's own program. Until every program has ended, it runs
  // ready tasks of the others (spinning, then parking when none comes).
  void finish_program(std::uint32_t p, ThreadCounters& tc) {
    // seq_cst RMW (a release): Dekker with the parked waiters as signal() (sync.hpp).
    programs_.fetch_add(1, std::memory_order_seq_cst);
    if (parking_.parked() != 0) parking_.wake(programs_);
    const std::uint64_t all = programs_target_;
    std::uint64_t v = 0;
    try {
      wait(programs_, [all](std::uint64_t s) { return s >= all; }, p, kNoTask, tc, v, 5, 0);
    } catch (...) {
      fail(std::current_exception());
    }
  }

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
  alignas(64) std::atomic<std::uint64_t> touched_{0};  // first-touch barrier arrivals
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

}  // namespace

std::unique_ptr<Executor> make_partition_executor(const ExecOptions& o) {
  return std::make_unique<PartitionExecutor>(o, detail::PartitionTestHooks{});
}

std::unique_ptr<Executor> detail::make_partition_executor_for_tests(
    const ExecOptions& o, const PartitionTestHooks& hooks) {
  if (o.threads == 0 || o.threads > 1024) return make_executor(Policy::kPartition, o);  // throws
  return std::make_unique<PartitionExecutor>(o, hooks);
}

}  // namespace tgraph::replay
