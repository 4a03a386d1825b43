// SPDX-License-Identifier: MIT
// Executors: run the tasks of a step graph on threads under one Policy.
#pragma once

#include <cstdint>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "tgraph/graph/assignment.hpp"
#include "tgraph/graph/step_graph.hpp"
#include "tgraph/replay/lowering.hpp"
#include "tgraph/replay/observer.hpp"
#include "tgraph/replay/policy.hpp"
#include "tgraph/replay/workload.hpp"

namespace tgraph::replay {

/// Default spin time before a waiting thread parks in the kernel (see docs/replay.md and
/// bench/replay: a futex hand-off costs 9-36 µs on this machine, a spinning one 0.1 µs).
inline constexpr std::int64_t kDefaultSpinNs = 50'000;

/// Default watchdog timeout (ExecOptions::timeout_ms): generous, a step of a real trace
/// takes milliseconds.
inline constexpr std::int64_t kDefaultTimeoutMs = 300'000;

/// How an executor runs.
struct ExecOptions {
  std::uint32_t threads = 1;  ///< threads (processors); partition: must equal Assignment::k
  bool pin = true;            ///< bind thread p to a core with hwloc (partition, barrier)
  std::int64_t spin_ns = kDefaultSpinNs;  ///< spin this long before parking (0: park at once)
  std::optional<CwMode> cw;               ///< default: kReduce for every policy
  /// Temporaries of kReduce; default: kPerProcessor for partition, kPerWriter for the
  /// dynamic policies (worksteal, barrier, starpu), kNone for sequential. A sequential run
  /// given the scope of another policy reproduces that policy's reduction order.
  std::optional<ReduceScope> reduce_scope;
  /// Partition only: drop the waits that program order on the producing processor already
  /// implies (a reducer waits for the last of another processor's writers). Off: one wait
  /// per cross-processor producer (for measuring what the reduction saves).
  bool elide_waits = true;
  /// Partition only: run the per-processor programs interleaved on the calling thread
  /// (deterministic, same plans and waits; the serial twin of the threaded executor).
  bool serial = false;
  /// Partition only: on a structure or assignment change, update the previous step's plan
  /// (only the processors whose task lists or wait points changed are rebuilt) instead of
  /// building it from scratch. Both give the same plan.
  bool incremental_plans = true;
  /// Partition only: also build every incrementally updated plan from scratch and throw
  /// std::logic_error when the two differ (tests).
  bool verify_plans = false;
  /// Barrier only: what one phase holds (default: one dependency level).
  BarrierRule barrier_rule = BarrierRule::kLevel;
  /// StarPU only: the scheduling policy (StarPU's names: lws, ws, eager, prio, dmda...).
  std::string starpu_sched = "lws";
  /// Partition only: the watchdog. A step during which no thread finishes a task or passes
  /// a wait for this long ends with std::runtime_error naming what each thread waits for or
  /// runs (0: no watchdog). Every thread is joined before run_step throws.
  std::int64_t timeout_ms = kDefaultTimeoutMs;
  /// With the watchdog: a step that still has not ended one timeout after the watchdog
  /// fired (a task body that never returns, which nothing can interrupt) prints the report
  /// on stderr and ends the process with exit status 1. For command-line tools.
  bool timeout_exits = false;
  /// Testing only: the completion of this task (original id) is never published, as if a
  /// wake-up were lost; its readers on other processors wait until the watchdog fires.
  std::optional<TaskId> test_lose_signal;
};

/// Counters of one thread in one step, kept by the executor itself.
struct ThreadCounters {
  std::uint64_t tasks = 0;          ///< task instances run
  std::uint64_t signals = 0;        ///< completion counters published for other threads
  std::uint64_t waits = 0;          ///< cross-thread wait points passed
  std::uint64_t blocked_waits = 0;  ///< waits whose condition did not hold at once
  std::uint64_t parks = 0;          ///< blocked waits that slept in the kernel
  std::int64_t wait_ns = 0;         ///< time in blocked waits
};

/// What one step cost.
struct StepStats {
  std::int64_t wall_ns = 0;   ///< whole step, structure build included
  std::int64_t build_ns = 0;  ///< lowering + plan build (0 when the plan was reused)
  /// The plan build alone, without lowering (0 when the plan was reused): the per-processor
  /// programs, updated from the previous step's plan where the policy can.
  std::int64_t rebuild_ns = 0;
  std::uint32_t rebuilt_procs = 0;  ///< processors whose program was (re)built this step
  std::int64_t prepare_ns = 0;  ///< plan lookup + build_ns + binding the workload
  bool rebuilt = false;       ///< a new plan was built for this step
  std::vector<ThreadCounters> threads;
  std::vector<std::uint32_t> loop_iterations;  ///< iterations each loop ran
  /// Sums over threads.
  std::uint64_t signals() const;
  std::uint64_t waits() const;
  std::uint64_t blocked_waits() const;
  std::uint64_t parks() const;
  std::int64_t wait_ns() const;
};

/// Runs steps. The structure of a step (lowering, per-thread task lists, signal and wait
/// points, phases) is built once per distinct (structure, assignment) and reused while it
/// repeats, as in the paper (section 3.2); its build time is part of the step's wall time.
///
///   auto ex = make_executor(Policy::kPartition, {.threads = 2});
///   SyntheticWorkload w;
///   w.set_step(g);
///   StepStats s = ex->run_step(g, &assignment, w);
///
/// An exception thrown by a task (or a loop condition) stops the step; every thread is
/// joined and the first exception is rethrown by run_step.
class Executor {
 public:
  virtual ~Executor();
  Executor(const Executor&) = delete;
  Executor& operator=(const Executor&) = delete;

  /// The policy this executor implements.
  Policy policy() const { return policy_; }
  /// Number of threads.
  std::uint32_t threads() const { return options_.threads; }
  /// Options in force.
  const ExecOptions& options() const { return options_; }
  /// How CW groups are lowered ("reduce" or "serialize" in reports).
  CwMode cw() const { return cw_mode(); }
  /// Where kReduce puts its temporaries.
  ReduceScope scope() const { return reduce_scope(); }
  /// Adds an observer (not owned; must outlive the executor's use).
  void add_observer(Observer& observer) { observers_.push_back(&observer); }
  /// Removes every observer.
  void clear_observers() { observers_.clear(); }
  /// Observers see loop iterations 0, 1 and every `stride`-th one only (default 1: all).
  /// For observers that sample (cost feedback): a clock read per task instance costs a few
  /// percent of a fine-grained step.
  void set_observe_stride(std::uint32_t stride) { observe_stride_ = stride == 0 ? 1 : stride; }

  /// Runs one step of `g` (edges derived). `a` is required by Policy::kPartition
  /// (a->k == threads()) and ignored by the others. Throws UsageError on a bad assignment.
  StepStats run_step(const StepGraph& g, const Assignment* a, Workload& w);

  /// Number of plans built so far.
  std::uint64_t plans_built() const { return plans_built_; }
  /// Plans for which an explicit Assignment::order could not be kept (it contradicted
  /// edges the lowering added, e.g. serialised CW writers) and program order was used.
  virtual std::uint64_t order_fallbacks() const { return 0; }
  /// The exec graph of the last step.
  const ExecGraph* last_exec() const { return last_exec_; }

 protected:
  Executor(Policy policy, ExecOptions options);
  /// Builds the policy's plan for `x` (called on a cache miss). Returns an opaque plan.
  virtual std::shared_ptr<void> build(const ExecGraph& x) = 0;
  /// Builds the plan for `x` from `previous`, the plan this executor built for the exec
  /// graph `previous_exec` (called on a cache miss after a step; the partition policy updates
  /// it incrementally). Default: build(x).
  virtual std::shared_ptr<void> rebuild(const ExecGraph& x, const ExecGraph& previous_exec,
                                        const void* previous);
  /// Processors whose program the build of `plan` computed (default: every thread).
  virtual std::uint32_t rebuilt_procs(const void* plan) const;
  /// Runs one step with a plan. Fills `stats.threads` and `stats.loop_iterations`.
  virtual void execute(void* plan, const ExecGraph& x, Workload& w, bool fresh,
                       StepStats& stats) = 0;
  /// The CW mode this executor uses.
  CwMode cw_mode() const;
  /// The reduction scope this executor uses with CwMode::kReduce.
  ReduceScope reduce_scope() const;

  std::vector<Observer*> observers_;
  std::uint32_t observe_stride_ = 1;
  ExecOptions options_;

 private:
  struct CacheEntry;
  Policy policy_;
  std::vector<std::shared_ptr<CacheEntry>> cache_;
  std::shared_ptr<CacheEntry> last_entry_;  // the plan of the previous step
  EdgeDeriver exec_edges_;                  // the last lowered graph's edges, by datum
  std::uint64_t plans_built_ = 0;
  const ExecGraph* last_exec_ = nullptr;
};

/// Creates an executor; throws UsageError for threads == 0 or above 1024 (the sequential
/// policy runs on one thread whatever `options.threads` asks).
std::unique_ptr<Executor> make_executor(Policy policy, const ExecOptions& options);

/// Thread p's processing unit under pinning (hwloc, one PU per core first), for reports.
int pinned_pu(std::uint32_t p);

}  // namespace tgraph::replay
