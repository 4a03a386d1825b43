// SPDX-License-Identifier: MIT
// Incremental dependency derivation (EdgeDeriver): per datum, the previous step's edges are
// carried over when the datum's access sequence did not change.
#include "tgraph/graph/incremental.hpp"

#include <algorithm>
#include <chrono>

#include "dependencies.hpp"

namespace tgraph {
namespace {

std::int64_t now_ns() {
  return std::chrono::duration_cast<std::chrono::nanoseconds>(
             std::chrono::steady_clock::now().time_since_epoch())
      .count();
}

// The edges of one datum from its access sequence [first, last) (program order), as
// StepGraph::derive_edges() finds them: loop bodies get their second pass over the same
// accesses from the end-of-body state. Appends to `edges` / `carried`, each sorted and
// without duplicates.
template <class Entry>
void derive_datum(const StepGraph& g, DatumId d, const Entry* first, const Entry* last,
                  std::vector<Edge>& edges, std::vector<Edge>& carried) {
  const std::size_t edges_at = edges.size(), carried_at = carried.size();
  const auto n = static_cast<TaskId>(g.tasks.size());
  detail::DatumState state;
  detail::EdgeSink main;
  main.out = &edges;
  for (const Entry* i = first; i < last;) {
    if (i->loop == kNoLoop) {
      detail::apply_access(state, i->task, {d, i->mode}, main);
      ++i;
      continue;
    }
    const Entry* j = i;
    while (j < last && j->loop == i->loop) ++j;
    for (const Entry* k = i; k < j; ++k) detail::apply_access(state, k->task, {d, k->mode}, main);
    detail::DatumState second_state = state;
    detail::EdgeSink second;
    second.out = &carried;
    second.offset = n;
    second.body_first = g.loops[i->loop].first;
    second.body_last = g.loops[i->loop].last;
    for (const Entry* k = i; k < j; ++k)
      detail::apply_access(second_state, k->task + n, {d, k->mode}, second);
    i = j;
  }
  auto sort_unique = [](std::vector<Edge>& v, std::size_t from) {
    const auto b = v.begin() + static_cast<std::ptrdiff_t>(from);
    std::sort(b, v.end(), detail::edge_less);
    v.erase(std::unique(b, v.end(),
                        [](const Edge& x, const Edge& y) { return x.from == y.from && x.to == y.to; }),
            v.end());
  };
  sort_unique(edges, edges_at);
  sort_unique(carried, carried_at);
}

// `by_datum` (edges grouped by datum) in StepGraph order: counting sort by target, then
// each target's few edges by source, datum and kind.
void assemble(const std::vector<Edge>& by_datum, std::size_t n, std::vector<Edge>& out) {
  std::vector<std::uint32_t> begin(n + 1, 0);
  for (const Edge& e : by_datum) ++begin[e.to + 1];
  for (std::size_t t = 0; t < n; ++t) begin[t + 1] += begin[t];
  out.resize(by_datum.size());
  std::vector<std::uint32_t> fill(begin.begin(), begin.end() - 1);
  for (const Edge& e : by_datum) out[fill[e.to]++] = e;
  for (std::size_t t = 0; t < n; ++t)
    if (begin[t + 1] - begin[t] > 1)
      std::sort(out.begin() + begin[t], out.begin() + begin[t + 1], detail::edge_less);
}

// Edges grouped by datum (stable), with the group offsets.
void group_edges(const std::vector<Edge>& edges, std::size_t n_data,
                 std::vector<std::uint32_t>& begin, std::vector<Edge>& out) {
  begin.assign(n_data + 1, 0);
  for (const Edge& e : edges) ++begin[e.datum + 1];
  for (std::size_t d = 0; d < n_data; ++d) begin[d + 1] += begin[d];
  out.resize(edges.size());
  std::vector<std::uint32_t> fill(begin.begin(), begin.end() - 1);
  for (const Edge& e : edges) out[fill[e.datum]++] = e;
}

}  // namespace

void EdgeDeriver::group_accesses(const StepGraph& g, ByDatum& out) {
  out.begin.assign(g.data.size() + 1, 0);
  for (const Access& a : g.accesses) ++out.begin[a.datum + 1];
  for (std::size_t d = 0; d < g.data.size(); ++d) out.begin[d + 1] += out.begin[d];
  out.entries.resize(g.accesses.size());
  std::vector<std::uint32_t> fill(out.begin.begin(), out.begin.end() - 1);
  for (TaskId t = 0; t < g.tasks.size(); ++t)
    for (const Access& a : g.accesses_of(t)) out.entries[fill[a.datum]++] = {t, a.mode, g.tasks[t].loop};
}

void EdgeDeriver::reset() {
  have_previous_ = false;
  previous_task_.clear();
  previous_names_.clear();
  previous_accesses_ = {};
  edge_begin_.clear();
  carried_begin_.clear();
  edges_by_datum_.clear();
  carried_by_datum_.clear();
}

void EdgeDeriver::remember(const StepGraph& g, ByDatum&& accesses,
                           std::unordered_map<StableKey, TaskId>&& keys, bool keyed) {
  have_previous_ = true;
  previous_keyed_ = keyed;
  previous_task_ = std::move(keys);
  previous_names_.resize(g.data.size());
  for (DatumId d = 0; d < g.data.size(); ++d)
    if (previous_names_[d] != g.data[d].name) previous_names_[d] = g.data[d].name;
  previous_accesses_ = std::move(accesses);
}

void EdgeDeriver::seed(const StepGraph& g) {
  ByDatum acc;
  group_accesses(g, acc);
  std::unordered_map<StableKey, TaskId> keys;
  bool keyed = true;
  keys.reserve(g.tasks.size());
  for (TaskId t = 0; t < g.tasks.size() && keyed; ++t) keyed = keys.emplace(g.tasks[t].key, t).second;
  remember(g, std::move(acc), std::move(keys), keyed);
  group_edges(g.edges, g.data.size(), edge_begin_, edges_by_datum_);
  group_edges(g.carried_edges, g.data.size(), carried_begin_, carried_by_datum_);
}

EdgeUpdate EdgeDeriver::derive(StepGraph& g) {
  const std::int64_t t0 = now_ns();
  EdgeUpdate u;
  ByDatum cur;
  group_accesses(g, cur);
  const auto n = static_cast<TaskId>(g.tasks.size());
  // New task -> previous task, by stable key; every key must name one task in each step.
  std::vector<TaskId> old_of(n, kNoTask);
  bool keyed = true;
  std::unordered_map<StableKey, TaskId> keys;
  keys.reserve(n);
  for (TaskId t = 0; t < n && keyed; ++t) keyed = keys.emplace(g.tasks[t].key, t).second;
  if (!have_previous_ || !previous_keyed_ || !keyed) {
    g.derive_edges();
    remember(g, std::move(cur), std::move(keys), keyed);
    group_edges(g.edges, g.data.size(), edge_begin_, edges_by_datum_);
    group_edges(g.carried_edges, g.data.size(), carried_begin_, carried_by_datum_);
    u.edges = g.edges.size() + g.carried_edges.size();
    u.ns = now_ns() - t0;
    return u;
  }
  std::size_t previous_n = 0;
  for (TaskId t = 0; t < n; ++t)
    if (auto it = previous_task_.find(g.tasks[t].key); it != previous_task_.end()) {
      old_of[t] = it->second;
      previous_n = std::max<std::size_t>(previous_n, it->second + 1);
    }
  std::vector<TaskId> new_of(previous_n, kNoTask);
  for (TaskId t = 0; t < n; ++t)
    if (old_of[t] != kNoTask) new_of[old_of[t]] = t;

  u.incremental = true;
  std::vector<std::uint32_t> edge_begin(g.data.size() + 1, 0), carried_begin(g.data.size() + 1, 0);
  std::vector<Edge> edges, carried;
  edges.reserve(edges_by_datum_.size());
  carried.reserve(carried_by_datum_.size());
  const auto previous_data = static_cast<DatumId>(previous_names_.size());
  for (DatumId d = 0; d < g.data.size(); ++d) {
    const Entry* nb = cur.entries.data() + cur.begin[d];
    const Entry* ne = cur.entries.data() + cur.begin[d + 1];
    if (nb != ne) {
      bool same = d < previous_data && previous_names_[d] == g.data[d].name;
      if (same) {
        const Entry* ob = previous_accesses_.entries.data() + previous_accesses_.begin[d];
        const Entry* oe = previous_accesses_.entries.data() + previous_accesses_.begin[d + 1];
        same = ne - nb == oe - ob;
        // Same tasks, modes, and the same accesses in loop bodies, grouped the same way.
        for (std::ptrdiff_t i = 0; same && i < ne - nb; ++i) {
          const Entry& x = nb[i];
          const Entry& y = ob[i];
          same = old_of[x.task] == y.task && x.mode == y.mode &&
                 (x.loop == kNoLoop) == (y.loop == kNoLoop) &&
                 (i == 0 || (x.loop == nb[i - 1].loop) == (y.loop == ob[i - 1].loop));
        }
      }
      if (same) {
        for (auto i = edge_begin_[d]; i < edge_begin_[d + 1]; ++i) {
          const Edge& e = edges_by_datum_[i];
          edges.push_back({new_of[e.from], new_of[e.to], d, e.kind});
        }
        for (auto i = carried_begin_[d]; i < carried_begin_[d + 1]; ++i) {
          const Edge& e = carried_by_datum_[i];
          carried.push_back({new_of[e.from], new_of[e.to], d, e.kind});
        }
        u.edges_reused += (edge_begin_[d + 1] - edge_begin_[d]) +
                          (carried_begin_[d + 1] - carried_begin_[d]);
        ++u.data_reused;
      } else {
        derive_datum(g, d, nb, ne, edges, carried);
        ++u.data_rederived;
      }
    }
    edge_begin[d + 1] = static_cast<std::uint32_t>(edges.size());
    carried_begin[d + 1] = static_cast<std::uint32_t>(carried.size());
  }
  assemble(edges, n, g.edges);
  assemble(carried, n, g.carried_edges);
  u.edges = g.edges.size() + g.carried_edges.size();
  remember(g, std::move(cur), std::move(keys), keyed);
  edge_begin_ = std::move(edge_begin);
  carried_begin_ = std::move(carried_begin);
  edges_by_datum_ = std::move(edges);
  carried_by_datum_ = std::move(carried);
  u.ns = now_ns() - t0;
  return u;
}

EdgeUpdate derive_edges_from(const StepGraph& previous, StepGraph& next) {
  EdgeDeriver deriver;
  deriver.seed(previous);
  return deriver.derive(next);
}

}  // namespace tgraph
