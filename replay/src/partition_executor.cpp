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
#include <atomic>
#include <exception>
#include <memory>
#include <mutex>
#include <stdexcept>
#include <string>
#include <thread>
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
          waited);
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
          step_seq_, [seen](std::uint64_t v) { return v > seen; }, never_abort_, parked, waited);
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
    const std::uint64_t value = parking_.wait(c, ok, abort_, parked, waited);
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
    tc.tasks += tasks;
    tc.signals += signals;
    counters_[p].c = tc;
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
  // Step context: written by the main thread before the step_seq_ store, read by workers
  // after acquiring it.
  const PartitionPlan* plan_ = nullptr;
  const ExecGraph* exec_ = nullptr;
  Workload* workload_ = nullptr;
  bool fresh_ = false;
  std::uint64_t epoch_ = 0;
  std::uint64_t steps_ = 0;
  alignas(64) std::atomic<std::uint64_t> step_seq_{0};
  alignas(64) std::atomic<std::uint64_t> finished_{0};
  alignas(64) std::atomic<std::uint64_t> touched_{0};  // first-touch barrier arrivals
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
