// SPDX-License-Identifier: MIT
// The partitioned executor: its plans, its steps, its worker threads, failures and the
// watchdog (partition_runtime.hpp; the walk of a program and the stealing have files of their
// own).
#include <exception>
#include <memory>
#include <mutex>
#include <string>
#include <vector>

#include "partition_report.hpp"
#include "partition_runtime.hpp"
#include "partition_serial.hpp"
#include "tgraph/graph/error.hpp"

namespace tgraph::replay::detail {

std::unique_ptr<PartitionPlan> PartitionExecutor::checked(const ExecGraph& x, PartitionPlan built) {
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

void PartitionExecutor::run(PartitionPlan& plan, const ExecGraph& x, Workload& w, bool fresh,
                            ExecStepStats& stats) {
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
        finished_, [target](std::uint64_t v) { return v >= target; }, never_abort_, parked, waited,
        [] { return false; }, [] { return false; }, &counters_[0].sleeping);
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

void PartitionExecutor::start_workers() {
  if (started_) return;
  started_ = true;
  if (options().pin) {
    main_binding_.save_once();  // restored when the executor is destroyed
    detail::pin_current_thread(0);
  }
  for (std::uint32_t p = 1; p < options().threads; ++p)
    workers_.emplace_back([this, p] { worker(p); });
}

void PartitionExecutor::worker(std::uint32_t p) {
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

void PartitionExecutor::fail(std::exception_ptr e) {
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

void PartitionExecutor::lose_signal(PartitionPlan& plan, const ExecGraph& x) const {
  if (!hooks_.lose_signal || *hooks_.lose_signal >= x.exec_of.size()) return;
  const TaskId t = x.exec_of[*hooks_.lose_signal];
  for (ProcPlan& pp : plan.procs)
    for (Op& op : pp.ops)
      if (op.kind == OpKind::kTask && op.task == t) {
        op.signal = false;
        if (op.combine == CombineRole::kOffer) op.combine = CombineRole::kNone;  // no arrival
      }
}

void PartitionExecutor::start_watchdog() {
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

std::string PartitionExecutor::stall_report() const {
  std::vector<detail::ThreadStand> threads(options().threads);
  for (std::uint32_t p = 0; p < threads.size(); ++p) {
    const Slot& s = counters_[p];
    // relaxed: diagnostics, a racy snapshot is fine.
    threads[p] = {s.wait_kind.load(std::memory_order_relaxed),
                  s.wait_id.load(std::memory_order_relaxed),
                  s.at_task.load(std::memory_order_relaxed),
                  s.inside.load(std::memory_order_relaxed),
                  s.inside_of.load(std::memory_order_relaxed)};
  }
  return detail::stall_report(*exec_, *plan_, threads);
}

}  // namespace tgraph::replay::detail

namespace tgraph::replay {

std::unique_ptr<Executor> make_partition_executor(const ExecOptions& o) {
  return std::make_unique<detail::PartitionExecutor>(o, detail::PartitionTestHooks{});
}

std::unique_ptr<Executor> detail::make_partition_executor_for_tests(
    const ExecOptions& o, const PartitionTestHooks& hooks) {
  if (o.threads == 0 || o.threads > 1024) return make_executor(Policy::kPartition, o);  // throws
  return std::make_unique<PartitionExecutor>(o, hooks);
}

}  // namespace tgraph::replay
