// SPDX-License-Identifier: MIT
// The critical path of a step with its loops unrolled: which task instances and edges it runs
// through, under the rules of compute_metrics (its length is the step's span).
#pragma once

#include <cstdint>
#include <vector>

#include "tgraph/graph/step_graph.hpp"

namespace tgraph::viz {

/// One task instance (iteration 0 outside loops).
struct TaskInstance {
  TaskId task = 0;
  std::uint32_t iteration = 0;
  friend bool operator==(const TaskInstance&, const TaskInstance&) = default;
};

/// How the path enters an instance from its predecessor.
enum class PathLink : std::uint8_t {
  kStart = 0,    ///< first instance of the path
  kEdge = 1,     ///< an intra-step edge (StepGraph::edges)
  kCarried = 2,  ///< a loop-carried edge (StepGraph::carried_edges)
  kLoopGate = 3  ///< the previous iteration's conditional break (loop control)
};
/// "start", "edge", "carried" or "loop gate".
const char* to_string(PathLink link);

/// The longest path of the unrolled step.
///
///   const CriticalPath cp = critical_path(g);  // g.edges derived
///   // cp.length_ns == compute_metrics(g).span_ns
struct CriticalPath {
  std::uint64_t length_ns = 0;
  std::vector<TaskInstance> instances;  ///< in execution order
  std::vector<PathLink> links;          ///< links[i]: how instances[i] is entered
  std::vector<std::uint32_t> edge_of;   ///< links[i] == kEdge/kCarried: index in that list
  /// Per task: how many of its instances lie on the path (loop iterations counted).
  std::vector<std::uint32_t> task_hits;
  /// Per edge of StepGraph::edges / carried_edges: how many times the path uses it.
  std::vector<std::uint32_t> edge_hits, carried_hits;
};

/// Computes the critical path of `g` (edges derived). Ties go to the loop gate, then to the
/// edge found first (intra edges in order, then carried edges).
CriticalPath critical_path(const StepGraph& g);

}  // namespace tgraph::viz
