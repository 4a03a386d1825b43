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
inline bool edge_less(const Edge& a, const Edge& b) {
  if (a.to != b.to) return a.to < b.to;
  if (a.from != b.from) return a.from < b.from;
  if (a.datum != b.datum) return a.datum < b.datum;
  return a.kind < b.kind;
}

/// Asks the kernel to back [p, p + bytes) with huge pages when it spans several (Linux
/// MADV_HUGEPAGE; a hint, ignored elsewhere or when refused). Large arrays filled once
/// then take one page fault per 2 MiB instead of one per 4 KiB.
void advise_huge_pages(void* p, std::size_t bytes);

/// v.reserve(n), the reserved range advised as huge pages before anything touches it.
template <class T>
void reserve_huge(std::vector<T>& v, std::size_t n) {
  v.reserve(n);
  advise_huge_pages(v.data(), v.capacity() * sizeof(T));
}

/// `g`'s accesses grouped by datum (a counting sort: linear in tasks, data and accesses).
void group_accesses(const StepGraph& g, AccessesByDatum& out);
/// The same with the per-datum fill cursors in `fill` (scratch, reused by the caller).
void group_accesses(const StepGraph& g, AccessesByDatum& out, std::vector<std::uint32_t>& fill);

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
/// The same with the edges per target already counted: `begin[t + 1]` holds target t's
/// count on entry (begin has tasks + 1 entries; it is consumed).
void assemble_counted(const std::vector<Edge>& by_datum, std::vector<std::uint32_t>& begin,
                      std::vector<Edge>& out);

}  // namespace tgraph::detail
