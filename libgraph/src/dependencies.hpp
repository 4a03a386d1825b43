// SPDX-License-Identifier: MIT
// The per-datum state machine of the dependency derivation, shared by derive_edges() and
// the incremental EdgeDeriver (internal to libgraph).
#pragma once

#include <cstddef>
#include <limits>
#include <vector>

#include "tgraph/graph/incremental.hpp"
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

/// `g`'s accesses grouped by datum (a counting sort: linear in tasks, data and accesses).
void group_accesses(const StepGraph& g, AccessesByDatum& out);

/// The edges of datum `d` from its access sequence [first, last) (program order), as
/// StepGraph::derive_edges() finds them: loop bodies get their second pass over the same
/// accesses from the end-of-body state. Appends to `edges` / `carried`, each datum's sorted
/// (edge_less) and without duplicates; throws when either would exceed `max_edges`.
/// `state` and `second_state` are scratch, their buffers reused from datum to datum.
void derive_datum(const StepGraph& g, DatumId d, const AccessEntry* first, const AccessEntry* last,
                  std::vector<Edge>& edges, std::vector<Edge>& carried, DatumState& state,
                  DatumState& second_state,
                  std::size_t max_edges = std::numeric_limits<std::size_t>::max());

/// `by_datum` (edges grouped by datum, each datum's in edge_less order) in StepGraph order
/// (edge_less over all): a counting sort by target, then each target's edges by source,
/// datum and kind (already in order when they come from one datum).
void assemble_by_target(const std::vector<Edge>& by_datum, std::size_t tasks,
                        std::vector<Edge>& out);

}  // namespace tgraph::detail
