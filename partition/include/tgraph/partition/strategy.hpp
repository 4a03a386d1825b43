// SPDX-License-Identifier: MIT
// Partitioning strategies behind one small interface, chosen by name.
#pragma once

#include <cstdint>
#include <functional>
#include <memory>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "tgraph/graph/assignment.hpp"
#include "tgraph/graph/step_graph.hpp"
#include "tgraph/graph/trace.hpp"
#include "tgraph/model/cost_model.hpp"

namespace tgraph::partition {

/// What METIS minimises.
enum class Objective : std::uint8_t { kCut = 0, kVolume = 1 };
/// "cut" or "vol".
std::string_view to_string(Objective o);
/// Parses "cut" / "vol"; otherwise an OptionError of the field "objective".
Objective parse_objective(std::string_view s);

/// Scotch's strategy flavour (SCOTCH_STRAT* flags).
enum class ScotchFlavour : std::uint8_t { kDefault = 0, kQuality = 1, kSpeed = 2, kBalance = 3 };
/// "default", "quality", "speed" or "balance".
std::string_view to_string(ScotchFlavour f);
/// Parses a flavour name; otherwise an OptionError of the field "scotch_strategy".
ScotchFlavour parse_scotch_flavour(std::string_view s);

/// How `sticky` rebalances when imbalance exceeds its threshold.
enum class Rebalance : std::uint8_t {
  kGreedy = 0,  ///< move whole objects from the most to the least loaded processor
  kScotch = 1,  ///< SCOTCH_graphRepart from the current assignment with a migration cost
};
/// "greedy" or "scotch".
std::string_view to_string(Rebalance r);
/// Parses a rebalance name; otherwise an OptionError of the field "rebalance".
Rebalance parse_rebalance(std::string_view s);

/// What `sticky` does when a step's shape changed too much to patch (solver loops merged or
/// split, or over a quarter of the tasks new).
enum class StickyFallback : std::uint8_t {
  kFresh = 0,        ///< the base method afresh, parts relabelled to the previous step's
  kRepartition = 1,  ///< SCOTCH_graphRepart from the incremental placement, migration cost per task
  kRefine = 2,       ///< local search from the incremental placement (units to their neighbours)
};
/// "fresh", "repartition" or "refine".
std::string_view to_string(StickyFallback f);
/// Parses a fallback name; otherwise an OptionError of the field "sticky_fallback".
StickyFallback parse_sticky_fallback(std::string_view s);

/// How each processor orders its tasks when the strategy gives no order of its own.
enum class TaskOrder : std::uint8_t {
  kProgram = 0,  ///< the step's program order (Assignment::order left empty)
  kList = 1,     ///< a list schedule of the mapping: longest path to the end first (list_order)
};
/// "program" or "list".
std::string_view to_string(TaskOrder o);
/// Parses an order name; otherwise an OptionError of the field "order".
TaskOrder parse_task_order(std::string_view s);

/// Knobs of the strategies; each strategy reads the ones it understands.
struct Options {
  double imbalance = 1.03;          ///< tolerated max load / mean load (METIS, Scotch)
  std::uint64_t seed = 0;           ///< METIS / Scotch / random seed (0: METIS's own default, as gpmetis)
  Objective objective = Objective::kCut;  ///< METIS objective
  std::uint32_t phases = 0;         ///< METIS multi-constraint: phases balanced separately (<2: off)
  /// sticky: the phases its METIS partitions (first step, fresh fallback) balance separately
  /// when `phases` is 0 (a solver step's CG phases synchronise every object of a collision
  /// group: balanced as a whole they leave each phase unbalanced; docs/partitioning.md)
  std::uint32_t sticky_phases = 2;
  /// With phases on (METIS multi-constraint): each dynamic loop holding at least this share
  /// of the step's work (cost x iterations) is balanced on its own, as one more constraint
  /// (task_phases; a loop's processors meet at every iteration). 0: off.
  double loop_share = 0.1;
  ScotchFlavour scotch = ScotchFlavour::kQuality;
  std::string sticky_base = "metis";  ///< sticky: strategy for the first step
  double sticky_threshold = 1.20;   ///< sticky: rebalance above this x the baseline imbalance
  Rebalance rebalance = Rebalance::kGreedy;  ///< sticky: how to rebalance
  StickyFallback sticky_fallback = StickyFallback::kFresh;  ///< sticky: when the shape changed
  /// sticky, Scotch repartitioning (rebalance or fallback): emraval, the weight of migrated
  /// load against the cut (quantised to 0.01 by Scotch)
  double migration_cost = 1.0;
  model::CostModel model = model::CostModel::defaults();  ///< list: communication cost estimate
  /// Every strategy but list (which orders itself): the order each processor runs its tasks
  TaskOrder order = TaskOrder::kProgram;
};

/// Options with their enumerations and cost model by name, as the command line and scripts
/// give them; options() checks the names (OptionError naming the field) and loads the model.
struct NamedOptions {
  Options values;                         ///< numbers and the sticky base method
  std::string objective = "cut";          ///< cut, vol
  std::string scotch_strategy = "quality";  ///< Options::scotch: default, quality, speed, balance
  std::string rebalance = "greedy";       ///< greedy, scotch
  std::string sticky_fallback = "fresh";  ///< fresh, repartition, refine
  std::string order = "program";          ///< program, list
  std::string model = "calibrated";       ///< calibrated, ideal (select_cost_model)
  std::string calibration;                ///< calibration file ("": the default one if present)

  /// The cost model named by `model` and `calibration`.
  model::CostModel cost_model() const;
  /// `values` with the named enumerations and the cost model filled in.
  Options options() const;
};

/// The previous step, for incremental strategies (both null for the first step).
struct Previous {
  const StepGraph* graph = nullptr;
  const Assignment* assignment = nullptr;
};

/// What a call cost and what it changed.
struct Stats {
  double partition_ms = 0.0;            ///< wall time of the strategy itself
  std::optional<std::int64_t> edgecut;  ///< library objective (METIS objval, Scotch cut), library units
  std::uint64_t matched_tasks = 0;      ///< tasks found in the previous step by stable key
  std::uint64_t moved_tasks = 0;        ///< matched tasks whose processor changed
  bool reused = false;    ///< sticky: previous assignment reused as is
  bool fallback = false;  ///< sticky: partitioned afresh and relabelled (shape changed too much)
  bool rebalanced = false;  ///< sticky: kept the assignment, then moved tasks to fix imbalance
  /// The strategy that placed the step when this one could not and fell back (owner on a
  /// step whose tasks have no object: "list"); empty when the strategy placed it itself.
  std::string placed_by;
  /// What the caller should be told (the command line prints them on stderr): a fallback
  /// and why, processors left without tasks.
  std::vector<std::string> warnings;
};

/// An assignment and its statistics.
struct Result {
  Assignment assignment;
  Stats stats;
};

/// A partitioning strategy. Adding one = one source file + one line in registry.cpp.
///
///   auto s = make_strategy("metis");
///   Result r = s->partition(step, 8, {}, Options{});
///   // r.assignment.proc[t] in [0, 8)
class Strategy {
 public:
  virtual ~Strategy() = default;
  /// Name under which the strategy is registered.
  virtual std::string_view name() const = 0;
  /// Partitions `g` (edges derived) over `k` processors. Validates the inputs (UsageError
  /// for k = 0 or an inconsistent previous step), times the call and counts the tasks that
  /// moved relative to `prev` (matched by stable key).
  Result partition(const StepGraph& g, std::uint32_t k, const Previous& prev,
                   const Options& options);

 private:
  virtual Result do_partition(const StepGraph& g, std::uint32_t k, const Previous& prev,
                              const Options& options) = 0;
};

/// Creates a strategy by name; throws UsageError listing the known names.
std::unique_ptr<Strategy> make_strategy(std::string_view name);
/// Names of all registered strategies, sorted.
std::vector<std::string> strategy_names();

/// One assignment per step, plus each step's statistics.
struct TracePartition {
  TraceAssignment assignment;
  std::vector<Stats> stats;
  /// The steps' warnings, each distinct text once with the steps it concerns
  /// ("... (steps 0-9, 10 of 10)").
  std::vector<std::string> warnings;
  /// The strategy that placed the steps: the method, or its fallback when every step fell
  /// back ("list" for owner on a trace without objects), or "method+fallback" when some did.
  std::string placed_by;
};

/// Runs strategy `method` on every step of `trace` in order, handing each step the previous
/// step and its assignment (what `sticky` needs).
TracePartition partition_trace(const Trace& trace, std::string_view method, std::uint32_t k,
                               const Options& options = {});

/// The strategy `tgraph replay` uses when none is given: `owner` (the paper's owner-compute
/// rule) when some task of the trace works on an object's data, else `list` (critical-path
/// list scheduling), which uses every processor the graph's parallelism allows.
std::string default_method(const Trace& trace);

/// Partitions one step given the previous one (null at the first step): the callback a live
/// run calls at each step (measure::run_live).
using StepPartitioner = std::function<Assignment(
    const StepGraph& g, std::uint32_t k, const StepGraph* prev_graph, const Assignment* prev)>;
/// Strategy `method` as a StepPartitioner (UsageError for an unknown name); each call's Stats
/// appended to `calls` when given.
StepPartitioner step_partitioner(std::string_view method, const Options& options = {},
                                 std::shared_ptr<std::vector<Stats>> calls = nullptr);

/// A quick assignment of `g` for a step that cannot wait for its strategy (O(tasks +
/// accesses)): every task found in `prev_graph` by stable key keeps its processor in `prev`;
/// the new ones go, in program order, to the processor holding most bytes of the data they
/// touch, else the least loaded (sticky's incremental placement, without its rebalance).
/// Without a previous step (both null): the owner-compute rule, `owner`. A live run applies
/// it at once and lets the strategy's own assignment follow from a background thread.
/// `match` (optional): match_by_key(g, *prev_graph), when the caller has it already.
Assignment carry_over(const StepGraph& g, std::uint32_t k, const StepGraph* prev_graph,
                      const Assignment* prev, const std::vector<TaskId>* match = nullptr);

/// Imbalance of `a` on `g` as its processors meet: the most loaded processor's work outside
/// the heavy loops (each dynamic loop holding at least `loop_share` of the step's work, cost
/// x iterations) plus, for each heavy loop, its most loaded processor's work in that loop,
/// over the mean load of the whole step. At least the whole step's max / mean: a loop's
/// processors wait for each other at every iteration, so a loop unbalanced one way is not
/// made up by another unbalanced the other way. loop_share 0: the whole step's max / mean.
double loop_imbalance(const StepGraph& g, const Assignment& a, double loop_share);

/// Renames the K part labels of `a` (a partition of `g`) so that as many tasks as possible,
/// matched in `prev` by stable key and counted once each, keep their previous processor: an
/// optimal assignment of labels (Hungarian algorithm on the K x K overlap), so no other
/// renaming moves fewer tasks. Returns the matched tasks that kept their processor; does
/// nothing (returns 0) without a previous step or when its K differs.
std::uint64_t relabel_to_previous(const StepGraph& g, const Previous& prev, Assignment& a);

/// Tasks of `g` matched in `prev` by stable key (the i-th task with a key matches the
/// i-th task with the same key); match[t] = task in prev or kNoTask.
std::vector<TaskId> match_by_key(const StepGraph& g, const StepGraph& prev);

}  // namespace tgraph::partition
