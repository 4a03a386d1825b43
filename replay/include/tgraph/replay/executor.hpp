// SPDX-License-Identifier: MIT
// Executors: run the tasks of a step graph on threads under one Policy.
#pragma once

#include <cstdint>
#include <memory>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "tgraph/graph/assignment.hpp"
#include "tgraph/graph/lowering.hpp"
#include "tgraph/graph/step_graph.hpp"
#include "tgraph/replay/observer.hpp"
#include "tgraph/replay/policy.hpp"
#include "tgraph/replay/workload.hpp"

namespace tgraph::replay {

namespace detail {
class ExecPlan;  // one step structure's plan, of the executor's own type (replay/src)
}  // namespace detail

/// Default spin time before a waiting thread parks in the kernel (see docs/replay.md and
/// bench/replay: a futex hand-off costs 9-36 µs on this machine, a spinning one 0.1 µs).
inline constexpr std::int64_t kDefaultSpinNs = 50'000;
/// How long the partition executor's waits spin at most, beyond spin_ns, while the thread
/// they wait for runs, where every thread has a core of its own (then they park).
inline constexpr std::int64_t kLongSpinNs = 1'000'000;

/// Default watchdog timeout (PartitionOptions::timeout_ms): generous, a step of a real trace
/// takes milliseconds.
inline constexpr std::int64_t kDefaultTimeoutMs = 300'000;

/// Options of the partition executor (Policy::kPartition) only.
struct PartitionOptions {
  /// Drop the waits that program order on the producing processor already implies (a
  /// reducer waits for the last of another processor's writers). Off: one wait per
  /// cross-processor producer (for measuring what the reduction saves).
  bool elide_waits = true;
  /// Run the per-processor programs interleaved on the calling thread (deterministic, same
  /// plans and waits; the serial twin of the threaded executor).
  bool serial = false;
  /// Reductions run by whichever of their processors arrives last: a reducer waiting for
  /// one partial sum from each of other processors, and the tasks after it on its processor
  /// that another processor waits for (a dot product's scalar), run on the thread that
  /// finishes its part last (the reducer's own, or a writer's right after its partial sum)
  /// instead of on the reducer's thread after the writers' signals: one cross-thread
  /// hand-off on the critical path of a dot product instead of two. The tasks and their
  /// order are the same, and so are the results; only which thread runs these few tasks
  /// changes (observers see the thread that ran them). Needs elide_waits; off: every task
  /// on its assigned processor.
  bool combine = true;
  /// Partition-guided stealing: a thread that would wait (for a producer, or at the end of
  /// its program for the others) runs ready tasks of the programs instead, its own first
  /// (ahead of its program order), then those of the processors with the most left. A
  /// processor's tasks keep their processor's temporaries and their order of cumulative
  /// writes (the results are the same bits as without); a loop's break task and the tasks
  /// of a combine are never taken. Off: every task on its assigned processor.
  bool steal = true;
  /// The watchdog. A step during which no thread finishes a task or passes a wait for this
  /// long ends with std::runtime_error naming what each thread waits for or runs (0: no
  /// watchdog). Every thread is joined before run_step throws.
  std::int64_t timeout_ms = kDefaultTimeoutMs;
  /// With the watchdog: a step that still has not ended one timeout after the watchdog
  /// fired (a task body that never returns, which nothing can interrupt) prints the report
  /// on stderr and ends the process with exit status 1. For command-line tools.
  bool timeout_exits = false;
};

/// Options of the barrier baseline (Policy::kBarrier) only.
struct BarrierOptions {
  BarrierRule rule = BarrierRule::kOmpFor;  ///< what one phase holds, where barriers go
};

/// Options of the StarPU baseline (Policy::kStarpu) only.
struct StarpuOptions {
  std::string sched = "lws";  ///< the scheduling policy (StarPU's names: lws, ws, eager...)
};

/// Options of the OpenMP-tasks baseline (Policy::kOmpTasks) only.
struct OmpTasksOptions {
  /// A `taskwait` after each iteration of an unrolled loop (what an OpenMP program testing
  /// convergence writes; libgomp's dependence lists stay short). Off: the whole step is
  /// submitted at once, as the other dynamic baselines unroll it.
  bool iteration_wait = true;
  /// The wait after each iteration (unrolled with iteration_wait, or live) is OpenMP 5.0's
  /// `taskwait depend(in: ...)` on the loop's break task: the submitting thread waits for
  /// the break (the residual's test) only, while the rest of the iteration runs on. Off: a
  /// plain `taskwait` drains every task submitted so far.
  bool wait_depend = false;
};

/// How an executor runs: the options every policy reads, then each policy's own (an
/// executor reads only its own part; the others are ignored).
struct ExecOptions {
  std::uint32_t threads = 1;  ///< threads (processors); partition: must equal Assignment::k
  /// Every policy: bind thread p (slot p of the runtime's team, arena or workers; the
  /// calling thread is slot 0) to pinned_pu(p), once per executor while it keeps its slot.
  bool pin = true;
  std::int64_t spin_ns = kDefaultSpinNs;  ///< spin this long before parking (0: park at once)
  std::optional<CwMode> cw;               ///< default: kReduce for every policy
  /// Temporaries of kReduce; default: kPerProcessor for partition, kPerWriter for the
  /// dynamic policies (worksteal, barrier, starpu, omp-tasks), kNone for sequential. omp-tasks
  /// with kNone leaves CW groups whole and declares them `mutexinoutset`. A sequential run
  /// given the scope of another policy reproduces that policy's reduction order.
  std::optional<ReduceScope> reduce_scope;
  /// On a structure or assignment change, update the previous step's lowered edges and (for
  /// the partition policy) its plan: only the processors whose task lists or wait points
  /// changed are rebuilt. Off: both are built from scratch. Both give the same result.
  bool incremental_plans = true;
  PartitionOptions partition;  ///< Policy::kPartition only
  BarrierOptions barrier;      ///< Policy::kBarrier only
  StarpuOptions starpu;        ///< Policy::kStarpu only
  OmpTasksOptions omp_tasks;   ///< Policy::kOmpTasks only
};

/// Counters of one thread in one step, kept by the executor itself.
struct ThreadCounters {
  std::uint64_t tasks = 0;          ///< task instances run
  std::uint64_t signals = 0;        ///< completion counters published for other threads
  std::uint64_t waits = 0;          ///< cross-thread wait points passed
  std::uint64_t blocked_waits = 0;  ///< waits whose condition did not hold at once
  std::uint64_t parks = 0;          ///< blocked waits that slept in the kernel
  std::int64_t wait_ns = 0;         ///< time in blocked waits
  std::uint64_t stolen = 0;         ///< of `tasks`, those of another processor's program
};

/// What one step of an executor cost (the engine's own step figures are samples::StepStats).
struct ExecStepStats {
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
///   ExecStepStats s = ex->run_step(g, &assignment, w);
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
  CwMode cw() const;
  /// Where kReduce puts its temporaries.
  ReduceScope scope() const;
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
  ExecStepStats run_step(const StepGraph& g, const Assignment* a, Workload& w);

  /// Number of plans built so far.
  std::uint64_t plans_built() const { return plans_built_; }
  /// Plans for which an explicit Assignment::order could not be kept (it contradicted
  /// edges the lowering added, e.g. serialised CW writers) and program order was used.
  virtual std::uint64_t order_fallbacks() const { return 0; }
  /// The exec graph of the last step.
  const ExecGraph* last_exec() const { return last_exec_; }

 protected:
  Executor(Policy policy, ExecOptions options);
  /// The observers added (for the executors' hot loops).
  const std::vector<Observer*>& observers() const { return observers_; }
  /// The stride set by set_observe_stride().
  std::uint32_t observe_stride() const { return observe_stride_; }

 private:
  struct CacheEntry;
  /// Builds the policy's plan for `x` (called on a cache miss); from `previous`, the plan
  /// this executor built for the previous step, when not null (the partition policy updates
  /// it incrementally). Implemented by detail::PlannedExecutor with the policy's plan type.
  virtual std::unique_ptr<detail::ExecPlan> build(const ExecGraph& x,
                                                  const detail::ExecPlan* previous) = 0;
  /// Processors whose program the build of `plan` computed.
  virtual std::uint32_t rebuilt_procs(const detail::ExecPlan& plan) const = 0;
  /// Runs one step with a plan. Fills `stats.threads` and `stats.loop_iterations`.
  virtual void execute(detail::ExecPlan& plan, const ExecGraph& x, Workload& w, bool fresh,
                       ExecStepStats& stats) = 0;

  std::vector<Observer*> observers_;
  std::uint32_t observe_stride_ = 1;
  ExecOptions options_;
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

/// The most threads `policy` can run in this build (StarPU: its STARPU_MAXCPUS CPU workers),
/// nullopt when only make_executor's own limit applies.
std::optional<std::uint32_t> max_threads(Policy policy);

/// Thread p's processing unit under pinning (hwloc, one PU per core first), for reports.
int pinned_pu(std::uint32_t p);

/// The OpenMP runtime the OpenMP policies (barrier, omp-tasks) of this process run on:
/// "gnu" (GCC's libgomp, which tgraph is built against) or "llvm" (LLVM's libomp, through
/// its libgomp-compatible entry points when it is preloaded: see docs/replay.md).
std::string_view openmp_runtime();
/// The file of LLVM's OpenMP runtime (libomp) found when tgraph was configured, for a
/// process that preloads it (empty when none was found).
std::string_view llvm_openmp_library();
/// Makes the process run on OpenMP runtime `name` ("gnu" or "llvm"): returns when it already
/// does; for "llvm", starts the process again (same arguments, /proc/self/cmdline) with
/// llvm_openmp_library() preloaded. OptionError("openmp_runtime") when it cannot.
void use_openmp_runtime(std::string_view name);

}  // namespace tgraph::replay
