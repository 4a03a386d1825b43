// SPDX-License-Identifier: MIT
// Dataflow edges from program order and accesses (paper section 3.1).
//
// Per datum we keep the state of the sequential program at the current point: the last
// writer (or the group of CW writers since the last plain write), the readers since then,
// and, for a CW group, the predecessors every member of the group shares. Edges:
//   * read  (R, RW): RAW from every last writer;
//   * write (W, RW): WAR from every reader since the last write; only when there is none,
//     WAW from the last writer(s) (with readers, the WAW edge is implied transitively and
//     is not emitted);
//   * CW: members of one CW group get no edge between them; each gets the group's shared
//     predecessors (readers since the last write, else the last writer(s)), and the next
//     reader or writer depends on all of them.
// Duplicate (from, to, datum) triples are removed; a task never depends on itself.
//
// Loop bodies are processed once for intra-iteration edges, then a second time from the
// state at the end of the body: edges from a first-pass task to a second-pass task are the
// loop-carried edges (iteration i -> i + 1).
//
// A datum's edges depend only on its own access sequence, so the derivation runs datum by
// datum over the accesses grouped by datum (derive_datum), which the incremental
// EdgeDeriver shares.
#include <sys/mman.h>

#include <algorithm>
#include <cstdint>
#include <limits>
#include <vector>

#include "dependencies.hpp"
#include "tgraph/graph/step_graph.hpp"

namespace tgraph {
namespace {

struct TooManyEdges {};

}  // namespace

namespace detail {

// Where the state machine's edges go: pass 1 emits every edge; pass 2 (offset != 0, ids >=
// offset are second-pass copies) keeps only edges from a first-pass body task to a
// second-pass task, as loop-carried edges (iteration i -> i + 1).
void EdgeSink::emit(TaskId from, TaskId to, DatumId d, EdgeKind kind) {
  if (from == to) return;
  if (out->size() >= max_edges) throw TooManyEdges{};
  if (offset == 0) {
    out->push_back({from, to, d, kind});
    return;
  }
  if (from >= offset) return;
  if (from < body_first || from >= body_last) return;
  if (from == to - offset) return;  // a task always follows its own previous iteration
  out->push_back({from, to - offset, d, kind});
}

void apply_access(DatumState& s, TaskId id, Access a, EdgeSink& sink) {
  switch (a.mode) {
    case AccessMode::R:
      for (TaskId w : s.writers) sink.emit(w, id, a.datum, EdgeKind::RAW);
      // A task's accesses are processed together: a repeated reader is the last one.
      if (s.readers.empty() || s.readers.back() != id) s.readers.push_back(id);
      break;
    case AccessMode::W:
    case AccessMode::RW:
      if (a.mode == AccessMode::RW)
        for (TaskId w : s.writers) sink.emit(w, id, a.datum, EdgeKind::RAW);
      if (!s.readers.empty()) {
        for (TaskId r : s.readers) sink.emit(r, id, a.datum, EdgeKind::WAR);
      } else if (a.mode == AccessMode::W) {
        for (TaskId w : s.writers) sink.emit(w, id, a.datum, EdgeKind::WAW);
      }
      s.writers.assign(1, id);
      s.readers.clear();
      s.cw_group = false;
      break;
    case AccessMode::CW:
      if (!(s.cw_group && s.readers.empty())) {
        // A new group: its members share what precedes the group.
        if (!s.readers.empty()) {
          s.group_preds = s.readers;
          s.group_kind = EdgeKind::WAR;
        } else {
          s.group_preds = s.writers;
          s.group_kind = EdgeKind::WAW;
        }
        s.writers.clear();
        s.readers.clear();
        s.cw_group = true;
      }
      for (TaskId p : s.group_preds) sink.emit(p, id, a.datum, s.group_kind);
      if (s.writers.empty() || s.writers.back() != id) s.writers.push_back(id);
      break;
  }
}

void advise_huge_pages(void* p, std::size_t bytes) {
#ifdef MADV_HUGEPAGE
  constexpr std::uintptr_t kHuge = std::uintptr_t{2} << 20;
  const auto begin = (reinterpret_cast<std::uintptr_t>(p) + kHuge - 1) & ~(kHuge - 1);
  const auto end = (reinterpret_cast<std::uintptr_t>(p) + bytes) & ~(kHuge - 1);
  if (end >= begin + 2 * kHuge)
    ::madvise(reinterpret_cast<void*>(begin), end - begin, MADV_HUGEPAGE);  // a hint only
#else
  (void)p;
  (void)bytes;
#endif
}

void group_accesses(const StepGraph& g, AccessesByDatum& out) {
  std::vector<std::uint32_t> fill;
  group_accesses(g, out, fill);
}

void group_accesses(const StepGraph& g, AccessesByDatum& out, std::vector<std::uint32_t>& fill) {
  out.begin.assign(g.data.size() + 1, 0);
  for (const Access& a : g.accesses) ++out.begin[a.datum + 1];
  for (std::size_t d = 0; d < g.data.size(); ++d) out.begin[d + 1] += out.begin[d];
  reserve_huge(out.entries, g.accesses.size());
  out.entries.resize(g.accesses.size());
  // Each datum's next free entry; begin[d] again once every access is placed.
  fill.assign(out.begin.begin(), out.begin.end() - 1);
  const auto n = static_cast<TaskId>(g.tasks.size());
  for (TaskId t = 0; t < n; ++t) {
    const Task& task = g.tasks[t];
    const Access* a = g.accesses.data() + task.access_begin;
    for (std::uint32_t i = 0; i < task.access_count; ++i)
      out.entries[fill[a[i].datum]++] = {t, a[i].mode, task.loop};
  }
}

namespace {

void clear(DatumState& s) {
  s.writers.clear();
  s.readers.clear();
  s.group_preds.clear();
  s.group_kind = EdgeKind::WAW;
  s.cw_group = false;
}

// Sorts [from, end) of `v` by edge_less (a datum's edges come out of the state machine
// almost sorted: skipped when they already are) and removes repeated (from, to) pairs.
void sort_unique_tail(std::vector<Edge>& v, std::size_t from) {
  const auto b = v.begin() + static_cast<std::ptrdiff_t>(from);
  if (!std::is_sorted(b, v.end(), edge_less)) std::sort(b, v.end(), edge_less);
  v.erase(std::unique(b, v.end(),
                      [](const Edge& x, const Edge& y) { return x.from == y.from && x.to == y.to; }),
          v.end());
}

}  // namespace

void derive_datum(const StepGraph& g, DatumId d, const AccessEntry* first, const AccessEntry* last,
                  std::vector<Edge>& edges, std::vector<Edge>& carried, DatumState& state,
                  DatumState& second_state, std::size_t max_edges) {
  const std::size_t edges_at = edges.size(), carried_at = carried.size();
  const auto n = static_cast<TaskId>(g.tasks.size());
  clear(state);
  EdgeSink main;
  main.out = &edges;
  main.max_edges = max_edges;
  for (const AccessEntry* i = first; i < last;) {
    if (i->loop() == kNoLoop) {
      apply_access(state, i->task, {d, i->mode()}, main);
      ++i;
      continue;
    }
    const AccessEntry* j = i;
    while (j < last && j->loop() == i->loop()) ++j;
    for (const AccessEntry* k = i; k < j; ++k) apply_access(state, k->task, {d, k->mode()}, main);
    // Second pass over the body from the end-of-body state: edges from a first-pass task
    // to a second-pass task are the loop-carried ones.
    second_state.writers.assign(state.writers.begin(), state.writers.end());
    second_state.readers.assign(state.readers.begin(), state.readers.end());
    second_state.group_preds.assign(state.group_preds.begin(), state.group_preds.end());
    second_state.group_kind = state.group_kind;
    second_state.cw_group = state.cw_group;
    EdgeSink second;
    second.out = &carried;
    second.max_edges = max_edges;
    second.offset = n;
    second.body_first = g.loops[i->loop()].first;
    second.body_last = g.loops[i->loop()].last;
    for (const AccessEntry* k = i; k < j; ++k)
      apply_access(second_state, k->task + n, {d, k->mode()}, second);
    i = j;
  }
  sort_unique_tail(edges, edges_at);
  sort_unique_tail(carried, carried_at);
}

void assemble_by_target(const std::vector<Edge>& by_datum, std::size_t tasks,
                        std::vector<Edge>& out) {
  std::vector<std::uint32_t> begin(tasks + 1, 0);
  for (const Edge& e : by_datum) ++begin[e.to + 1];
  assemble_counted(by_datum, begin, out);
}

void assemble_counted(const std::vector<Edge>& by_datum, std::vector<std::uint32_t>& begin,
                      std::vector<Edge>& out) {
  const std::size_t tasks = begin.size() - 1;
  for (std::size_t t = 0; t < tasks; ++t) begin[t + 1] += begin[t];
  reserve_huge(out, by_datum.size());
  out.resize(by_datum.size());
  // begin[t] is target t's next free slot; after the scatter it is where t + 1 starts.
  for (const Edge& e : by_datum) out[begin[e.to]++] = e;
  std::uint32_t from = 0;
  for (std::size_t t = 0; t < tasks; ++t) {
    const auto b = out.begin() + from, e = out.begin() + begin[t];
    if (e - b > 1 && !std::is_sorted(b, e, edge_less)) std::sort(b, e, edge_less);
    from = begin[t];
  }
}

}  // namespace detail

void StepGraph::derive_edges() { derive_edges(std::numeric_limits<std::size_t>::max()); }

bool StepGraph::derive_edges(std::size_t max_edges) {
  edges.clear();
  carried_edges.clear();
  try {
    derive_edges_unchecked(max_edges);
  } catch (const TooManyEdges&) {
    edges.clear();
    carried_edges.clear();
    edges.shrink_to_fit();
    carried_edges.shrink_to_fit();
    return false;
  }
  return true;
}

namespace {

// derive_edges' temporaries, kept per thread from one call to the next: a step of 10^7
// tasks needs about 1 GB of them, and memory fresh from the kernel is zeroed page by page
// on first touch (44 % of a 10^7-task derivation here when every call allocated anew). What
// the largest step derived on a thread needed stays allocated for the next one.
struct DeriveScratch {
  detail::AccessesByDatum by_datum;
  std::vector<std::uint32_t> fill, intra_begin, carried_begin;
  std::vector<Edge> intra, carried;
  detail::DatumState state, second_state;
};

}  // namespace

// Datum by datum (each datum's edges depend on its own access sequence only): the accesses
// grouped by datum, one state machine run per datum over its sequence, then the edges put
// in target order. Every pass is linear in tasks, data, accesses and edges, and works on
// contiguous arrays (the state machine's scratch is reused from datum to datum, the arrays
// from call to call on one thread).
void StepGraph::derive_edges_unchecked(std::size_t max_edges) {
  thread_local DeriveScratch s;
  detail::group_accesses(*this, s.by_datum, s.fill);
  s.intra.clear();
  s.carried.clear();
  // Most steps have one to two edges per access: reserved (address space only) so that
  // the list rarely grows by copying.
  detail::reserve_huge(s.intra, 2 * accesses.size() + 16);
  // Edges per target, counted while each datum's edges are still in cache.
  s.intra_begin.assign(tasks.size() + 1, 0);
  s.carried_begin.assign(tasks.size() + 1, 0);
  const detail::AccessEntry* entries = s.by_datum.entries.data();
  for (DatumId d = 0; d < data.size(); ++d) {
    const std::uint32_t b = s.by_datum.begin[d], e = s.by_datum.begin[d + 1];
    if (b == e) continue;
    const std::size_t intra_at = s.intra.size(), carried_at = s.carried.size();
    detail::derive_datum(*this, d, entries + b, entries + e, s.intra, s.carried, s.state,
                         s.second_state, max_edges);
    for (std::size_t i = intra_at; i < s.intra.size(); ++i) ++s.intra_begin[s.intra[i].to + 1];
    for (std::size_t i = carried_at; i < s.carried.size(); ++i)
      ++s.carried_begin[s.carried[i].to + 1];
  }
  s.by_datum = {};  // released before the edges are assembled: the peak stays one copy
  detail::assemble_counted(s.intra, s.intra_begin, edges);
  detail::assemble_counted(s.carried, s.carried_begin, carried_edges);
}

}  // namespace tgraph
