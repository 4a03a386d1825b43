// SPDX-License-Identifier: MIT
// The method x K grid of `tgraph compare`, and the summaries `tgraph partition` reports.
#pragma once

#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "tgraph/graph/trace.hpp"
#include "tgraph/partition/evaluate.hpp"
#include "tgraph/partition/strategy.hpp"

namespace tgraph::partition {

/// What partitioning a whole trace cost and changed: the steps' Stats added up.
struct PartitionSummary {
  std::size_t steps = 0;
  double partition_ms = 0.0;
  std::optional<std::int64_t> edgecut;  ///< sum over the steps that report one
  std::uint64_t moved_tasks = 0;        ///< tasks (by stable key) whose processor changed
  std::uint64_t reused_steps = 0;       ///< sticky: previous assignment reused as is
  std::uint64_t fallback_steps = 0;     ///< sticky: fresh partition + relabelling
  std::uint64_t rebalanced_steps = 0;   ///< sticky: kept assignment, tasks moved for balance
};

/// Adds up the per-step statistics of partition_trace().
PartitionSummary summarize(const std::vector<Stats>& stats);

/// `tgraph partition`: every step of the trace file `trace_path` partitioned with `method` on
/// `k` processors (an OptionError of the field "k" when 0), the assignment written to
/// `output` unless it is empty; each step's `edgecut` is the cut of library_graph(step) by
/// its assignment, whatever objective the method's library reported.
TracePartition partition_file(const std::string& trace_path, const std::string& method,
                              std::uint32_t k, const Options& options, const std::string& output);

/// The JSON of a trace's partition: method, k, the summary, `output` and one object per step.
std::string partition_json(const TracePartition& tp, const std::string& output);
/// A trace's partition as text: method, K, time, edgecut, moves (sticky: reused, fallback,
/// rebalanced steps), and the file written when `output` is not empty.
std::string partition_text(const TracePartition& tp, const std::string& output);

/// One cell of the grid: a method at one K, partitioned and evaluated.
struct CompareRow {
  std::string method;
  std::uint32_t k = 1;
  /// Rows of the `sticky` migration-cost sweep: the cost (emraval) they ran with, falling
  /// back by Scotch repartitioning from the incremental placement.
  std::optional<double> migration_cost;
  /// Not dominated, among the rows at this K, in (moved tasks, predicted makespan): no other
  /// row moves no more tasks with no longer a makespan, one of the two strictly.
  bool pareto_makespan = false;
  /// Likewise in (moved tasks, cut bytes).
  bool pareto_cut = false;
  PartitionSummary partition;
  Report report;  ///< evaluate() of the assignment (per-step reports included)
};

/// Sticky's moved tasks at one K against the METIS baselines in the same grid.
struct StickyMoves {
  std::uint32_t k = 1;
  std::uint64_t sticky = 0;
  std::optional<std::uint64_t> metis;          ///< when `metis` is in the grid
  std::optional<std::uint64_t> metis_relabel;  ///< when `metis-relabel` is in the grid
  /// sticky / metis (empty when metis is absent or moved nothing).
  std::optional<double> over_metis() const;
  /// sticky / metis-relabel (empty when metis-relabel is absent or moved nothing).
  std::optional<double> over_metis_relabel() const;
};

/// The whole grid.
struct Comparison {
  std::string model;                      ///< cost model source
  std::vector<CompareRow> rows;           ///< methods outer, K inner, in the order given
  std::vector<StickyMoves> sticky_moves;  ///< one per K when `sticky` is in the grid
  /// What the `sticky` rows (not the sweep rows) do when solver loops merge or split.
  StickyFallback sticky_fallback = StickyFallback::kRefine;
};

/// Partitions `trace` with every method at every K (partition_trace) and evaluates each
/// assignment with `options.model`; then, for each cost in `sticky_migration_costs`, `sticky`
/// at every K with `sticky_fallback = kRepartition` and that `migration_cost`. Marks each
/// K's Pareto points. Throws UsageError for an unknown method, K = 0 or a negative cost
/// before any work.
///
///   Comparison c = compare(trace, {"metis", "metis-relabel", "sticky"}, {2, 4, 8}, Options{});
///   std::cout << comparison_table(c);
Comparison compare(const Trace& trace, const std::vector<std::string>& methods,
                   const std::vector<std::uint32_t>& ks, const Options& options = {},
                   const std::vector<double>& sticky_migration_costs = {});

/// compare of the trace file `trace` with the same arguments, its comparison_csv written to
/// `csv` unless empty: comparison_json and a newline when `json`, else comparison_table.
std::string compare_file(const std::string& trace, const std::vector<std::string>& methods,
                         const std::vector<std::uint32_t>& ks, const Options& options,
                         const std::vector<double>& sticky_migration_costs,
                         const std::string& csv, bool json);

/// The row's name in tables: the method, or "sticky@COST" for a sweep row.
std::string row_label(const CompareRow& row);

/// The comparison's JSON: {"trace", "model", "rows": [...], "sticky_moves": [...]}.
std::string comparison_json(const Comparison& c, const std::string& trace_name);
/// The comparison's CSV: one header line, one line per row.
std::string comparison_csv(const Comparison& c);
/// The comparison's text table, followed by sticky's step kinds and moves per K and the
/// Pareto points of each K.
std::string comparison_table(const Comparison& c);

}  // namespace tgraph::partition
