// SPDX-License-Identifier: MIT
// Live runs: the engine's own task bodies (recorded in deferred mode) executed by an
// executor step after step, timed against the uninstrumented engine, and the bit-for-bit
// comparison of final states.
#pragma once

#include <cstdint>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "tgraph/measure/engine.hpp"
#include "tgraph/measure/method.hpp"
#include "tgraph/measure/state.hpp"
#include "tgraph/measure/step_record.hpp"
#include "tgraph/partition/strategy.hpp"
#include "tgraph/replay/executor.hpp"

namespace tgraph::measure {

/// The outcome of a live run's check of its final state.
enum class Check : unsigned char {
  kIdentical = 0,  ///< bit for bit the reference's
  kDiffers = 1,    ///< see LiveResult::difference and LiveResult::values
  /// Not bit-identical to the plain run, every value within LiveResult::rounding_bound of it
  /// (CheckReference::kPlain only: the twin must be bit-identical).
  kWithinRounding = 2,
};

/// "identical", "differs" or "within-rounding".
std::string_view to_string(Check check);

/// What a live run's check compares the final state with.
enum class CheckReference : unsigned char {
  /// The serial twin: a sequential run with the run's own assignments and reduction order
  /// (the partition policy's serial executor, the dynamic policies' per-writer temporaries);
  /// any difference is a fault.
  kTwin = 0,
  /// The engine's own plain sequential run (LiveEngine::plain_step, uninstrumented, program
  /// order): what a user's sequential loop computes, off by the rounding of the reductions
  /// the run sums in another order.
  kPlain = 1,
};

/// "twin" or "plain".
std::string_view to_string(CheckReference reference);

/// What a live run does.
struct LiveOptions {
  replay::Policy policy = replay::Policy::kPartition;
  replay::ExecOptions exec;  ///< threads, pinning, spin, CW mode
  std::uint32_t steps = 10;
  std::uint32_t repeat = 1;  ///< timed passes (medians reported)
  /// Time the uninstrumented engine too, pass by pass interleaved, on each of the first
  /// min(threads, 4) cores the run uses (pinned), keeping the fastest.
  bool baseline = true;
  bool observe = true;            ///< one more pass with observers (threads, kinds), plus a
                                  ///< sequential one for the per-kind comparison
  bool check = false;             ///< compare the final state with a sequential reference
  CheckReference check_reference = CheckReference::kTwin;  ///< that reference
  /// Keep the assignment each step of the first pass ran (LiveResult::assignments): what a
  /// model of this run must simulate, carried-over steps included.
  bool keep_assignments = false;
  std::uint32_t cost_stride = 8;  ///< cost feedback samples loop iterations 0, 1, every n-th
  /// Partition policy: call the partitioner at every step. Default: at the first step, once
  /// costs were first measured, when the structure changed, and when the trigger
  /// (RepartitionTrigger: drift past `rebalance_tolerance` whose gain over
  /// `repartition_horizon` steps exceeds the cost of rebuilding the plans and migrating)
  /// fires; otherwise the assignment, and so the plan, is kept. Imbalances are
  /// partition::loop_imbalance with `loop_share` (each heavy loop's share counted apart).
  bool repartition_every_step = false;
  double rebalance_tolerance = 0.05;
  std::uint32_t repartition_horizon = 10;
  double loop_share = partition::Options{}.loop_share;
  /// Partition policy: the partitioner runs on a helper thread while steps go on, and its
  /// assignment is applied at the first step boundary after it is ready; a step whose
  /// structure changed gets partition::carry_over of the assignment in use at once. False:
  /// the step waits for the partitioner (its time is then all in partition_ns).
  bool background_partition = true;
  /// Let the engine skip recording while the structure repeats (false: record every step).
  bool reuse_structure = true;
  /// Keep the observed pass's timeline (LiveResult::timeline; `tgraph run --timeline F`).
  bool keep_timeline = false;
};

/// The sticky threshold a live run partitions with unless told otherwise: its trigger's
/// 1 + rebalance_tolerance. A live run pays every point of imbalance in wall time, and its
/// trigger already waits for that tolerance (at sticky's default 1.20, torso's loops ran up
/// to 20 % off for 60 steps). `tgraph run` and the experiments' live runs both use it.
inline double live_sticky_threshold(const LiveOptions& o) { return 1.0 + o.rebalance_tolerance; }
/// The strategies' options of a live run that sets none of its own: the defaults with
/// live_sticky_threshold(o).
inline partition::Options live_strategy_options(const LiveOptions& o) {
  partition::Options po;
  po.sticky_threshold = live_sticky_threshold(o);
  return po;
}

/// Mean duration of the instances of one task kind.
struct KindTime {
  std::string kind;
  std::uint64_t instances = 0;    ///< instances timed
  double mean_ns = 0;             ///< in the observed run of the policy
  double sequential_mean_ns = 0;  ///< in the observed sequential run (0: not run)
};

/// One step of a live run (medians over the timed passes; threads from the observed pass).
/// StepRecord::wall_ns: record + partition + prepare + execute.
struct LiveStepMeasure : StepRecord {
  std::int64_t record_ns = 0;        ///< coordination code in deferred mode, edges derived
  /// Time the step waited for partitioning: cost feedback, the quick carry-over of a changed
  /// structure, and the partitioner itself when it runs in the foreground.
  std::int64_t partition_ns = 0;
  /// The partitioner's own time off the critical path (jobs finished by this step's start).
  std::int64_t background_partition_ns = 0;
  std::int64_t prepare_ns = 0;       ///< plan lookup, lowering and plan build, binding
  std::int64_t graph_update_ns = 0;  ///< edge derivation within record_ns, first pass
  std::int64_t execute_ns = 0;       ///< the executor running the tasks
  std::int64_t baseline_ns = 0;      ///< the same step of the uninstrumented engine
  bool rebuilt = false;              ///< a plan was built for this step (first pass)
  bool recorded = true;              ///< the engine recorded the step (false: program reused)
  bool partitioned = false;  ///< an assignment was made or asked for at this step (first pass)
  bool reassigned = false;   ///< the assignment in use changed at this step (first pass)
  std::vector<std::uint32_t> loop_iterations;  ///< first pass
};

/// A dynamic loop that ran another number of iterations live than in program order: the
/// runs took different paths (a convergence test decided otherwise on values a rounding
/// apart), and their states differ by the loop's tolerance, not by rounding.
struct IterationDifference {
  std::uint32_t step = 0;
  std::uint32_t loop = 0;       ///< by index in the step's loops
  std::uint32_t in_order = 0;   ///< iterations in program order (the plain run's)
  std::uint32_t live = 0;       ///< iterations in the checked pass
};

/// A whole live run.
struct LiveResult {
  replay::Policy policy = replay::Policy::kPartition;
  std::uint32_t threads = 1;
  CwMode cw = CwMode::kReduce;
  ReduceScope scope = ReduceScope::kNone;
  std::vector<LiveStepMeasure> steps;
  std::vector<std::int64_t> pass_wall_ns;
  /// Uninstrumented engine passes, by core (thread p's core, p < min(threads, 4); one
  /// unpinned series when pinning is off).
  std::vector<std::vector<std::int64_t>> baseline_core_pass_wall_ns;
  std::int64_t wall_ns = 0;  ///< median pass
  /// The fastest core's median uninstrumented pass (0: not timed): the sequential engine
  /// where it runs best, so that a slow core of a VM never flatters the speed-up.
  std::int64_t baseline_wall_ns = 0;
  double speedup = 0;  ///< baseline_wall_ns / wall_ns
  /// The speed-up the measured cores allow: sum over the timed cores of baseline_wall_ns /
  /// that core's median (2.0 for two equal cores; less when one is slower). 0 when fewer
  /// cores than threads were timed.
  double core_bound = 0;
  std::uint64_t plans_built = 0, order_fallbacks = 0;
  std::uint64_t signals = 0, waits = 0, blocked_waits = 0, parks = 0;  ///< first pass
  std::vector<KindTime> kinds;                                         ///< observed passes
  /// Partition policy with LiveOptions::keep_assignments: the first pass's, one per step.
  std::vector<Assignment> assignments;
  /// The check of the final state (LiveOptions::check; nullopt: not checked).
  std::optional<Check> check;
  CheckReference check_reference = CheckReference::kTwin;  ///< what it was compared with
  std::string reference;  ///< that reference in words
  std::optional<StateDifference> difference;  ///< the first difference (any reference)
  /// Not bit-identical: how far apart the values are (max_abs_diff, max_rel_diff).
  std::optional<ValueDifference> values;
  /// kPlain: the relative bound max_rel_diff is held to, reduction_order_bound(
  /// longest_reduction, reduction_rounds) (docs/instrumenting.md).
  double rounding_bound = 0;
  std::uint64_t longest_reduction = 0;  ///< terms of the run's longest CW reduction
  std::uint64_t reduction_rounds = 0;   ///< the steps plus their loop iterations
  /// kPlain, not bit-identical: the first loop whose iteration count differs (then the check
  /// says kDiffers whatever the distance).
  std::optional<IterationDifference> iterations;
  std::size_t data_compared = 0;
  /// The observed pass's lost time by cause, summed over the steps (StepRecord::attribution):
  /// its serial phases, its bodies against the kinds' means in the observed sequential pass.
  std::optional<explain::Attribution> attribution;
  /// The observed pass's timeline with its serial phases and those sequential costs
  /// (LiveOptions::keep_timeline).
  std::optional<Timeline> timeline;
};

/// Runs `options.steps` steps of fresh engines from `make_engine` under `options.policy`
/// (`partitioner` is required for replay::Policy::kPartition): `repeat` timed passes, each preceded
/// by a pass of the uninstrumented engine, then the observed passes and the check.
///
/// The check (LiveOptions::check_reference) compares the final state of the first timed pass
/// with the twin, a sequential run that uses the same reduction order (for the partition
/// policy the serial twin of the executor with the assignments of the first timed pass, for
/// the dynamic policies the sequential executor with per-writer temporaries, for
/// CwMode::kSerialize and the sequential policy the plain program order), or with the
/// engine's plain run (plain_step, steps times).
LiveResult run_live(const EngineFactory& make_engine, const partition::StepPartitioner* partitioner,
                    const LiveOptions& options);

/// A method choice as a live run takes it, the one translation every verb and experiment
/// that runs a method live calls: `options.policy` set to the choice's; under the partition
/// policy the strategy's partitioner for run_live (partition::step_partitioner with
/// `strategy`, each call's Stats appended to `calls` when given), else none.
std::optional<partition::StepPartitioner> live_partitioner(
    const MethodChoice& choice, const partition::Options& strategy, LiveOptions& options,
    std::shared_ptr<std::vector<partition::Stats>> calls = nullptr);

/// `tgraph run`: a samples scene live under one method.
struct SceneRun {
  std::string scene;  ///< a built-in scene or a scene file
  samples::SceneOptions scene_options;
  std::optional<std::uint32_t> steps;  ///< default: the scene's
  MethodChoice method;
  partition::NamedOptions strategy;  ///< the partition policy's partitioner
  LiveOptions live;                  ///< its policy, steps and loop_share come from the above
  bool json = false;                 ///< report as one JSON line (else text)
};

/// The run and its report.
struct SceneRunReport {
  LiveResult result;
  std::string report;  ///< the JSON line or the text, ready to print
};

/// Runs `run.scene` live (run_live over make_live_engine), the partition policy's steps
/// partitioned by partition::step_partitioner; InputError for an unknown scene, OptionError
/// for the options run_live refuses.
SceneRunReport run_scene(const SceneRun& run);

}  // namespace tgraph::measure
