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

#include "tgraph/graph/step_graph.hpp"

namespace tgraph {
namespace {

struct DatumState {
  std::vector<TaskId> writers;      // last plain writer, or the CW group since
  std::vector<TaskId> readers;      // readers since the last write
  std::vector<TaskId> group_preds;  // shared predecessors of the current CW group
  EdgeKind group_kind = EdgeKind::WAW;
  bool cw_group = false;
};

struct TooManyEdges {};

class Extractor {
 public:
  Extractor(const StepGraph& g, std::vector<Edge>& out, std::size_t max_edges)
      : g_(g), out_(out), state_(g.data.size()), max_edges_(max_edges) {}

  // Second-pass mode: ids >= offset_ are second-pass copies; only edges from a first-pass
  // body task to a second-pass task are emitted (as carried edges).
  void set_pass(TaskId offset, TaskId body_first, TaskId body_last) {
    offset_ = offset;
    body_first_ = body_first;
    body_last_ = body_last;
  }

  void process(TaskId t) {
    const TaskId id = t + offset_;
    for (const Access& a : g_.accesses_of(t)) {
      DatumState& s = state_[a.datum];
      switch (a.mode) {
        case AccessMode::R:
          for (TaskId w : s.writers) emit(w, id, a.datum, EdgeKind::RAW);
          // A task's accesses are processed together: a repeated reader is the last one.
          if (s.readers.empty() || s.readers.back() != id) s.readers.push_back(id);
          break;
        case AccessMode::W:
        case AccessMode::RW:
          if (a.mode == AccessMode::RW)
            for (TaskId w : s.writers) emit(w, id, a.datum, EdgeKind::RAW);
          if (!s.readers.empty()) {
            for (TaskId r : s.readers) emit(r, id, a.datum, EdgeKind::WAR);
          } else if (a.mode == AccessMode::W) {
            for (TaskId w : s.writers) emit(w, id, a.datum, EdgeKind::WAW);
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
          for (TaskId p : s.group_preds) emit(p, id, a.datum, s.group_kind);
          if (s.writers.empty() || s.writers.back() != id) s.writers.push_back(id);
          break;
      }
    }
  }

  std::vector<DatumState>& state() { return state_; }

 private:
  void emit(TaskId from, TaskId to, DatumId d, EdgeKind kind) {
    if (from == to) return;
    if (out_.size() >= max_edges_) throw TooManyEdges{};
    if (offset_ == 0) {
      out_.push_back({from, to, d, kind});
      return;
    }
    // Second pass: keep only first-pass body sources (carried), drop the rest.
    if (from >= offset_) return;
    if (from < body_first_ || from >= body_last_) return;
    if (from == to - offset_) return;  // a task always follows its own previous iteration
    out_.push_back({from, to - offset_, d, kind});
  }

  const StepGraph& g_;
  std::vector<Edge>& out_;
  std::vector<DatumState> state_;
  std::size_t max_edges_;
  TaskId offset_ = 0;
  TaskId body_first_ = 0;
  TaskId body_last_ = 0;
};

void sort_unique(std::vector<Edge>& edges) {
  std::sort(edges.begin(), edges.end(), [](const Edge& a, const Edge& b) {
    if (a.to != b.to) return a.to < b.to;
    if (a.from != b.from) return a.from < b.from;
    return a.datum < b.datum;
  });
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
      // the data the body touches (the others cannot produce carried edges).
      Extractor second(*this, carried_edges, max_edges);
      for (TaskId u = loop.first; u < loop.last; ++u)
        for (const Access& a : accesses_of(u)) second.state()[a.datum] = main.state()[a.datum];
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
