// SPDX-License-Identifier: MIT
// Work, span and parallelism of a step graph, loops taken into account.
#pragma once

#include <cstdint>
#include <map>
#include <string>
#include <vector>

#include "tgraph/graph/step_graph.hpp"

namespace tgraph {

/// Summary numbers of one step.
struct Metrics {
  std::uint64_t tasks = 0;
  std::uint64_t edges = 0;          ///< intra-step + loop-carried edges
  std::uint64_t data = 0;
  std::uint64_t loops = 0;
  std::uint64_t loop_iterations = 0;  ///< sum over loops
  std::uint64_t work_ns = 0;        ///< sum of cost x runs
  std::uint64_t span_ns = 0;        ///< critical path with loops unrolled
  double parallelism = 0.0;         ///< work / span (0 for an empty step)
  std::map<std::string, std::uint64_t> per_kind;  ///< task count per kind
};

/// Computes the metrics; `g.edges` must be derived.
///
/// The span is the longest path of the graph unrolled over its loops' iterations:
/// iteration i+1 of a loop starts no earlier than the conditional break of
/// iteration i (loop control is a synchronisation point), and loop-carried edges
/// link a writer in iteration i to its reader in iteration i+1.
Metrics compute_metrics(const StepGraph& g);

/// Earliest finish time (ns) of every task in the last iteration it runs, under
/// unlimited processors; the span is the maximum. Same rules as compute_metrics.
std::vector<std::uint64_t> earliest_finish(const StepGraph& g);

/// The edges into every task in CSR form: for i in [begin[t], begin[t + 1]), edges[edge[i]]
/// ends at task t (in the order of the list).
struct IncomingEdges {
  std::vector<std::uint32_t> begin;  ///< tasks + 1 offsets into `edge`
  std::vector<std::uint32_t> edge;   ///< indices into the edge list
};

/// The incoming edges of each of `tasks` tasks (earliest_finish and viz's critical path).
IncomingEdges incoming_edges(std::size_t tasks, const std::vector<Edge>& edges);

/// Costs that noise cannot bend: per step, each task's cost replaced by the median of its
/// cost over the steps of the same structure (same_structure: the same tasks with the same
/// stable keys, in the same order). A task interrupted in one step (a preempted thread
/// while capturing) keeps its usual cost; a step whose structure no other step has keeps
/// its own costs. Indexed [step][task].
std::vector<std::vector<std::uint64_t>> robust_costs(const std::vector<StepGraph>& steps);

/// The step counted in tasks rather than time: every task run costs 1.
struct UnitMetrics {
  std::uint64_t work_tasks = 0;  ///< task runs (a loop body task counts once per iteration)
  std::uint64_t span_tasks = 0;  ///< hop count of the critical path, loops unrolled
  double parallelism = 0.0;      ///< work_tasks / span_tasks (0 for an empty step)
};

/// Work and span under unit costs, by the rules of compute_metrics (the span is
/// compute_metrics' span with every task's cost set to 1): the shape of the graph without
/// its timing, so it does not move with a preempted task.
UnitMetrics compute_unit_metrics(const StepGraph& g);

}  // namespace tgraph
