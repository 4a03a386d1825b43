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

class Extractor {
 public:
  Extractor(const StepGraph& g, std::vector<Edge>& out) : g_(g), out_(out), state_(g.data.size()) {}

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
          if (std::find(s.readers.begin(), s.readers.end(), id) == s.readers.end())
            s.readers.push_back(id);
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
          if (std::find(s.writers.begin(), s.writers.end(), id) == s.writers.end())
            s.writers.push_back(id);
          break;
      }
    }
  }

  std::vector<DatumState>& state() { return state_; }

 private:
  void emit(TaskId from, TaskId to, DatumId d, EdgeKind kind) {
    if (from == to) return;
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

void StepGraph::derive_edges() {
  edges.clear();
  carried_edges.clear();
  Extractor main(*this, edges);
  std::size_t next_loop = 0;
  const auto n = static_cast<TaskId>(tasks.size());
  for (TaskId t = 0; t < n;) {
    if (next_loop < loops.size() && loops[next_loop].first == t) {
      const Loop& loop = loops[next_loop++];
      for (TaskId u = loop.first; u < loop.last; ++u) main.process(u);
      // Second pass over the body from the end-of-body state, on a copy.
      Extractor second(*this, carried_edges);
      second.state() = main.state();
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
