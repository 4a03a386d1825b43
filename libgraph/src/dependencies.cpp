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
#include <algorithm>
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

bool edge_less(const Edge& a, const Edge& b) {
  if (a.to != b.to) return a.to < b.to;
  if (a.from != b.from) return a.from < b.from;
  if (a.datum != b.datum) return a.datum < b.datum;
  return a.kind < b.kind;
}

}  // namespace detail

namespace {

using detail::DatumState;
using detail::EdgeSink;

class Extractor {
 public:
  Extractor(const StepGraph& g, std::vector<Edge>& out, std::size_t max_edges)
      : g_(g), state_(g.data.size()) {
    sink_.out = &out;
    sink_.max_edges = max_edges;
  }

  // Second-pass mode (see EdgeSink).
  void set_pass(TaskId offset, TaskId body_first, TaskId body_last) {
    sink_.offset = offset;
    sink_.body_first = body_first;
    sink_.body_last = body_last;
  }

  void process(TaskId t) {
    const TaskId id = t + sink_.offset;
    for (const Access& a : g_.accesses_of(t)) detail::apply_access(state_[a.datum], id, a, sink_);
  }

  std::vector<DatumState>& state() { return state_; }

 private:
  const StepGraph& g_;
  std::vector<DatumState> state_;
  EdgeSink sink_;
};

void sort_unique(std::vector<Edge>& edges) {
  // The kind breaks ties so that of duplicate (from, to, datum) triples emitted with two
  // kinds (a task both reading and cumulatively writing a datum that a later RW task
  // updates) the same one is kept whatever order the edges were emitted in.
  std::sort(edges.begin(), edges.end(), detail::edge_less);
  edges.erase(std::unique(edges.begin(), edges.end(),
                          [](const Edge& a, const Edge& b) {
                            return a.from == b.from && a.to == b.to && a.datum == b.datum;
                          }),
              edges.end());
}

}  // namespace

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

void StepGraph::derive_edges_unchecked(std::size_t max_edges) {
  Extractor main(*this, edges, max_edges);
  std::size_t next_loop = 0;
  const auto n = static_cast<TaskId>(tasks.size());
  for (TaskId t = 0; t < n;) {
    if (next_loop < loops.size() && loops[next_loop].first == t) {
      const Loop& loop = loops[next_loop++];
      for (TaskId u = loop.first; u < loop.last; ++u) main.process(u);
      // Second pass over the body from the end-of-body state, on a copy of the states of
      // the data the body touches (the others cannot produce carried edges). Each datum's
      // state is copied once: a scalar every object reads would otherwise copy its reader
      // list once per access, quadratic in the objects.
      Extractor second(*this, carried_edges, max_edges);
      std::vector<char> copied(data.size(), 0);
      for (TaskId u = loop.first; u < loop.last; ++u)
        for (const Access& a : accesses_of(u))
          if (!copied[a.datum]) {
            copied[a.datum] = 1;
            second.state()[a.datum] = main.state()[a.datum];
          }
      second.set_pass(n, loop.first, loop.last);
      for (TaskId u = loop.first; u < loop.last; ++u) second.process(u);
      t = loop.last;
      continue;
    }
    main.process(t);
    ++t;
  }
  sort_unique(edges);
  sort_unique(carried_edges);
}

}  // namespace tgraph
