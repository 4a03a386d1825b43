// SPDX-License-Identifier: MIT
// Task -> processor maps.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "tgraph/graph/step_graph.hpp"

namespace tgraph {

using ProcId = std::uint32_t;

/// Task -> processor for one step, with an optional execution order per processor.
struct Assignment {
  std::uint32_t k = 1;                 ///< number of processors
  std::vector<ProcId> proc;            ///< proc[task] in [0, k)
  /// order[p] = tasks of processor p in execution order; empty = program order.
  std::vector<std::vector<TaskId>> order;
  friend bool operator==(const Assignment&, const Assignment&) = default;
};

/// One assignment per step of a trace, plus how it was made.
struct TraceAssignment {
  std::string method;
  std::uint32_t k = 1;
  std::vector<Assignment> steps;
  std::vector<double> partition_ms;    ///< time spent partitioning each step
  friend bool operator==(const TraceAssignment&, const TraceAssignment&) = default;
};

/// Why `a` cannot run `g` on `k` processors, or empty when it can: a.k == k >= 1, one
/// processor in [0, k) per task, and an order (when given) that lists each processor's own
/// tasks, every task exactly once. Callers turn the reason into their error type.
///
///   if (std::string why = validate(g, a, 4); !why.empty()) throw UsageError(why);
std::string validate(const StepGraph& g, const Assignment& a, std::uint32_t k);

/// Tasks of processor `p` in execution order (program order unless `a.order` says otherwise).
std::vector<TaskId> tasks_of(const Assignment& a, ProcId p);

/// The dependencies of one step that run from tasks on processor `from` to tasks on `to`.
struct QuotientEdge {
  ProcId from = 0;
  ProcId to = 0;
  std::uint64_t deps = 0;          ///< intra-step dependencies (StepGraph::edges)
  std::uint64_t carried_deps = 0;  ///< loop-carried ones (StepGraph::carried_edges)
  std::uint64_t bytes = 0;         ///< datum bytes of both, one datum per dependency
  /// Datum versions (and loop decisions) `from` sends to `to` in one execution of the step;
  /// 0 unless a simulation filled it in (partition::step_quotient).
  std::uint64_t signals = 0;
  friend bool operator==(const QuotientEdge&, const QuotientEdge&) = default;
};

/// An assignment's quotient graph of one step: a node per processor, an edge per ordered
/// pair of processors that dependencies join. Summed over its edges, `deps + carried_deps`
/// and `bytes` are the cut that `tgraph evaluate` reports.
struct QuotientGraph {
  std::vector<std::uint64_t> load_ns;  ///< per processor: sum of cost x runs of its tasks
  std::vector<std::uint64_t> tasks;    ///< per processor: tasks assigned to it
  std::vector<QuotientEdge> edges;     ///< from != to, sorted by (from, to)
};

/// The quotient graph of `g` (edges derived) under `a`, which must fit it (validate).
///
///   const QuotientGraph q = quotient_graph(g, a);   // q.load_ns[p], q.edges[i].bytes
QuotientGraph quotient_graph(const StepGraph& g, const Assignment& a);

}  // namespace tgraph
