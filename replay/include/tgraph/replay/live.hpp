// SPDX-License-Identifier: MIT
// Live runs: the engine's own task bodies (recorded in deferred mode) executed by an
// executor step after step, timed against the uninstrumented engine, and the bit-for-bit
// comparison of final states.
#pragma once

#include <cstdint>
#include <functional>
#include <memory>
#include <optional>
#include <span>
#include <string>
#include <vector>

#include "tgraph/graph/assignment.hpp"
#include "tgraph/graph/cumulative.hpp"
#include "tgraph/graph/step_graph.hpp"
#include "tgraph/replay/executor.hpp"
#include "tgraph/replay/observer.hpp"
#include "tgraph/replay/workload.hpp"

namespace tgraph::replay {

/// Runs the bodies and loop conditions of a deferred step. CW writers whose datum has an
/// Accumulator and whose write the lowering redirected to a temporary run with that
/// redirection installed (tgraph::accumulate), and reducers add the temporaries into the
/// datum in the lowering's fixed order; CW groups of data without one are serialised.
class ProgramWorkload : public Workload {
 public:
  /// `accumulators` by datum (nullptr: not reducible); empty: none is.
  ProgramWorkload(std::span<const std::function<void()>> bodies,
                  std::span<const std::function<bool()>> conditions,
                  std::span<const Accumulator* const> accumulators = {});
  ProgramWorkload() = default;
  /// The next step's bodies (same structure: the plan and its temporaries are kept).
  void set_program(std::span<const std::function<void()>> bodies,
                   std::span<const std::function<bool()>> conditions,
                   std::span<const Accumulator* const> accumulators = {});
  void bind(const ExecGraph& exec) override;
  bool needs_touch(DatumId d) const override;
  void first_touch(DatumId d) override;
  const std::vector<bool>* reducible() const override { return &reducible_; }
  void run(const TaskRun& r) override;
  bool stop_after(LoopId loop, std::uint32_t iteration) override;

 private:
  std::span<const std::function<void()>> bodies_;
  std::span<const std::function<bool()>> conditions_;
  std::span<const Accumulator* const> accumulators_;
  std::vector<bool> reducible_;                 // by original datum
  const ExecGraph* exec_ = nullptr;
  std::vector<std::shared_ptr<void>> temps_;    // by exec datum (temporaries only)
  std::vector<std::uint8_t> redirected_;        // by exec task: writes a temporary
};

/// One named piece of state (a datum's storage).
struct StateRegion {
  std::string name;
  const void* ptr = nullptr;
  std::uint64_t bytes = 0;
};

/// A copy of the bytes of some regions.
struct StateSnapshot {
  std::vector<std::string> names;
  std::vector<std::vector<std::uint8_t>> bytes;
};

/// Copies the regions' bytes.
StateSnapshot snapshot(std::span<const StateRegion> regions);

/// First difference between two snapshots of the same regions.
struct StateDifference {
  std::string datum;                  ///< name of the first differing region
  std::uint64_t offset = 0;           ///< first differing byte in it
  std::uint64_t differing_bytes = 0;  ///< in that region
};

/// nullopt when equal bit for bit.
std::optional<StateDifference> compare(const StateSnapshot& expected, const StateSnapshot& actual);
/// "first differing datum <datum> (byte <offset>, <differing_bytes> bytes differ)".
std::string to_string(const StateDifference& d);

/// One step of an engine recorded in deferred mode: nothing has run yet.
struct LiveStep {
  /// True: the engine recorded nothing because this step has the structure of the last one
  /// it recorded (same tasks, same bodies, which read the state through the same pointers):
  /// the runner executes the previous program again (paper section 3.2) and the other
  /// fields are empty.
  bool reuse_previous = false;
  StepGraph graph;                                ///< edges derived, costs may be 0
  std::vector<std::function<void()>> bodies;      ///< by task (empty for a loop's break)
  std::vector<std::function<bool()>> conditions;  ///< by loop: leave after this iteration?
  std::vector<const Accumulator*> accumulators;   ///< by datum, or nullptr
  std::int64_t graph_update_ns = 0;  ///< deriving the graph's edges (part of recording)
};

/// The engine side of a live run (the physics engine behind a small interface; see the
/// adapter over samples::Scene in samples/src/live_engine.cpp).
class LiveEngine {
 public:
  virtual ~LiveEngine() = default;
  /// Runs the coordination code of the next step in deferred mode (or, when `allow_reuse`,
  /// reports that the last recorded program applies again: LiveStep::reuse_previous).
  virtual LiveStep record_step(bool allow_reuse) = 0;
  /// Runs the next step uninstrumented, in program order (the sequential engine).
  virtual void plain_step() = 0;
  /// Storage of the state to compare bit for bit (after the steps).
  virtual std::vector<StateRegion> state() const = 0;
};

/// Makes a fresh engine (every pass starts from the scene's initial state).
using EngineFactory = std::function<std::unique_ptr<LiveEngine>()>;

/// Chooses the partition of step `g` on `k` processors; `prev_graph` / `prev` are the last
/// step's graph and assignment (nullptr at the first step). Costs in `g` are those measured
/// in earlier steps (sampled), 1 for tasks never run.
using LivePartitioner = std::function<Assignment(const StepGraph& g, std::uint32_t k,
                                                 const StepGraph* prev_graph,
                                                 const Assignment* prev)>;

/// What a live run does.
struct LiveOptions {
  Policy policy = Policy::kPartition;
  ExecOptions exec;            ///< threads, pinning, spin, CW mode
  std::uint32_t steps = 10;
  std::uint32_t repeat = 1;    ///< timed passes (medians reported)
  /// Time the uninstrumented engine too, pass by pass interleaved, on each of the first
  /// min(threads, 4) cores the run uses (pinned), keeping the fastest.
  bool baseline = true;
  bool observe = true;         ///< one more pass with observers (threads, kinds), plus a
                               ///< sequential one for the per-kind comparison
  bool check = false;          ///< compare the final state with a sequential reference
  std::uint32_t cost_stride = 8;  ///< cost feedback samples loop iterations 0, 1, every n-th
  /// Partition policy: call the partitioner at every step. Default: only when the structure
  /// changed or the last assignment's imbalance under the newly measured costs exceeds
  /// 1 + rebalance_tolerance (otherwise the assignment, and so the plan, is kept).
  bool repartition_every_step = false;
  double rebalance_tolerance = 0.05;
  /// Let the engine skip recording while the structure repeats (false: record every step).
  bool reuse_structure = true;
};

/// Mean duration of the instances of one task kind.
struct KindTime {
  std::string kind;
  std::uint64_t instances = 0;     ///< instances timed
  double mean_ns = 0;              ///< in the observed run of the policy
  double sequential_mean_ns = 0;   ///< in the observed sequential run (0: not run)
};

/// One step of a live run (medians over the timed passes; threads from the observed pass).
struct LiveStepMeasure {
  std::int64_t wall_ns = 0;       ///< record + partition + prepare + execute
  std::int64_t record_ns = 0;     ///< coordination code in deferred mode, edges derived
  std::int64_t partition_ns = 0;  ///< the partitioner callback
  std::int64_t prepare_ns = 0;    ///< plan lookup, lowering and plan build, binding
  std::int64_t build_ns = 0;      ///< lowering and plan build (0: plan reused), first pass
  std::int64_t rebuild_ns = 0;    ///< the plan part of build_ns (no lowering), first pass
  std::uint32_t rebuilt_procs = 0;  ///< processors whose program was (re)built, first pass
  std::int64_t graph_update_ns = 0;  ///< edge derivation within record_ns, first pass
  std::int64_t execute_ns = 0;    ///< the executor running the tasks
  std::int64_t baseline_ns = 0;   ///< the same step of the uninstrumented engine
  bool rebuilt = false;           ///< a plan was built for this step (first pass)
  bool recorded = true;           ///< the engine recorded the step (false: program reused)
  bool partitioned = false;       ///< the partitioner was called (first pass)
  std::vector<std::uint32_t> loop_iterations;   ///< first pass
  std::vector<StatsObserver::Thread> threads;   ///< observed pass
};

/// A whole live run.
struct LiveResult {
  Policy policy = Policy::kPartition;
  std::uint32_t threads = 1;
  CwMode cw = CwMode::kReduce;
  ReduceScope scope = ReduceScope::kNone;
  std::vector<LiveStepMeasure> steps;
  std::vector<std::int64_t> pass_wall_ns;
  /// Uninstrumented engine passes, by core (thread p's core, p < min(threads, 4); one
  /// unpinned series when pinning is off).
  std::vector<std::vector<std::int64_t>> baseline_core_pass_wall_ns;
  std::int64_t wall_ns = 0;           ///< median pass
  /// The fastest core's median uninstrumented pass (0: not timed): the sequential engine
  /// where it runs best, so that a slow core of a VM never flatters the speed-up.
  std::int64_t baseline_wall_ns = 0;
  double speedup = 0;                 ///< baseline_wall_ns / wall_ns
  /// The speed-up the measured cores allow: sum over the timed cores of baseline_wall_ns /
  /// that core's median (2.0 for two equal cores; less when one is slower). 0 when fewer
  /// cores than threads were timed.
  double core_bound = 0;
  std::uint64_t plans_built = 0, order_fallbacks = 0;
  std::uint64_t signals = 0, waits = 0, blocked_waits = 0, parks = 0;  ///< first pass
  std::vector<KindTime> kinds;        ///< observed passes
  /// --check: "identical", "differs" (then `difference`) or empty when not checked.
  std::string check;
  std::string check_reference;        ///< what the final state was compared with
  std::optional<StateDifference> difference;
  std::size_t data_compared = 0;
};

/// Runs `options.steps` steps of fresh engines from `make_engine` under `options.policy`
/// (`partitioner` is required for Policy::kPartition): `repeat` timed passes, each preceded
/// by a pass of the uninstrumented engine, then the observed passes and the check.
///
/// The check compares the final state with a sequential run that uses the same reduction
/// order: for the partition policy the serial twin of the executor with the assignments of
/// the first timed pass, for the dynamic policies the sequential executor with per-writer
/// temporaries, for `--cw serialize` and the sequential policy the plain program order.
LiveResult run_live(const EngineFactory& make_engine, const LivePartitioner* partitioner,
                    const LiveOptions& options);

/// The result as one JSON object (keys as `tgraph replay --json` where they mean the same).
std::string to_json(const LiveResult& r);
/// `tgraph run --json`: to_json(r) plus the scene and the method (strategy or policy).
std::string to_json(const LiveResult& r, const std::string& scene, const std::string& method);
/// `tgraph run`'s text report of `r`: a run of `scene` with `method` (strategy or policy),
/// `repeat` timed passes; the check line when one was made.
std::string to_text(const LiveResult& r, const std::string& scene, const std::string& method,
                    std::uint32_t repeat);

}  // namespace tgraph::replay
