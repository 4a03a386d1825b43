// SPDX-License-Identifier: MIT
// The per-datum state machine of the dependency derivation, shared by derive_edges() and
// the incremental EdgeDeriver (internal to libgraph).
#pragma once

#include <cstddef>
#include <limits>
#include <vector>

#include "tgraph/graph/step_graph.hpp"

namespace tgraph::detail {

/// The sequential program's state of one datum at the current point.
struct DatumState {
  std::vector<TaskId> writers;      ///< last plain writer, or the CW group since
  std::vector<TaskId> readers;      ///< readers since the last write
  std::vector<TaskId> group_preds;  ///< shared predecessors of the current CW group
  EdgeKind group_kind = EdgeKind::WAW;
  bool cw_group = false;
};

/// Where edges go. Pass 1 (offset 0) keeps every edge but self loops; pass 2 over a loop
/// body (ids >= offset are second-pass copies) keeps only edges from a first-pass task of
/// the body [body_first, body_last) to a second-pass task, as loop-carried edges.
struct EdgeSink {
  std::vector<Edge>* out = nullptr;
  std::size_t max_edges = std::numeric_limits<std::size_t>::max();
  TaskId offset = 0;
  TaskId body_first = 0;
  TaskId body_last = 0;
  /// Appends the edge if this pass keeps it; throws when out would exceed max_edges.
  void emit(TaskId from, TaskId to, DatumId d, EdgeKind kind);
};

/// Task `id` accesses datum `a.datum` (state `s`) with `a.mode`: emits the edges and
/// updates the state (the rules are in dependencies.cpp's header comment).
void apply_access(DatumState& s, TaskId id, Access a, EdgeSink& sink);

/// The order of StepGraph::edges: by target, source, datum, then kind.
bool edge_less(const Edge& a, const Edge& b);

}  // namespace tgraph::detail
