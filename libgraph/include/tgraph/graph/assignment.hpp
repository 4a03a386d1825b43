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

}  // namespace tgraph
