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

bool EdgeDeriver::KeyTable::build(const StepGraph& g) {
  std::size_t size = 16;
  while (size < 2 * g.tasks.size()) size *= 2;
  mask_ = size - 1;
  keys_.assign(size, 0);
  tasks_.assign(size, kNoTask);
  for (TaskId t = 0; t < g.tasks.size(); ++t) {
    const StableKey k = g.tasks[t].key;
    std::size_t i = (k ^ (k >> 29)) & mask_;
    while (tasks_[i] != kNoTask) {
      if (keys_[i] == k) return false;
      i = (i + 1) & mask_;
    }
    keys_[i] = k;
    tasks_[i] = t;
  }
  return true;
}

TaskId EdgeDeriver::KeyTable::find(StableKey k) const {
  if (tasks_.empty()) return kNoTask;
  for (std::size_t i = (k ^ (k >> 29)) & mask_;; i = (i + 1) & mask_) {
    if (tasks_[i] == kNoTask) return kNoTask;
    if (keys_[i] == k) return tasks_[i];
  }
}

void EdgeDeriver::reset() {
  have_previous_ = false;
  previous_task_ = {};
  previous_names_.clear();
  previous_accesses_ = {};
  edge_begin_.clear();
  carried_begin_.clear();
  edges_by_datum_.clear();
  carried_by_datum_.clear();
}

// current_task_ holds g's keys (KeyTable::build) when this is called.
void EdgeDeriver::remember(const StepGraph& g, ByDatum&& accesses, bool keyed) {
  have_previous_ = true;
  previous_keyed_ = keyed;
  std::swap(previous_task_, current_task_);
  previous_names_.resize(g.data.size());
  for (DatumId d = 0; d < g.data.size(); ++d)
    if (previous_names_[d] != g.data[d].name) previous_names_[d] = g.data[d].name;
  previous_accesses_ = std::move(accesses);
}

void EdgeDeriver::seed(const StepGraph& g) {
  ByDatum acc;
  detail::group_accesses(g, acc);
  const bool keyed = current_task_.build(g);
  remember(g, std::move(acc), keyed);
  group_edges(g.edges, g.data.size(), edge_begin_, edges_by_datum_);
  group_edges(g.carried_edges, g.data.size(), carried_begin_, carried_by_datum_);
}

EdgeUpdate EdgeDeriver::derive(StepGraph& g) {
  const std::int64_t t0 = now_ns();
  EdgeUpdate u;
  ByDatum cur;
  detail::group_accesses(g, cur);
  const auto n = static_cast<TaskId>(g.tasks.size());
  // New task -> previous task, by stable key; every key must name one task in each step.
  std::vector<TaskId> old_of(n, kNoTask);
  const bool keyed = current_task_.build(g);
  if (!have_previous_ || !previous_keyed_ || !keyed) {
    g.derive_edges();
    remember(g, std::move(cur), keyed);
    group_edges(g.edges, g.data.size(), edge_begin_, edges_by_datum_);
    group_edges(g.carried_edges, g.data.size(), carried_begin_, carried_by_datum_);
    u.edges = g.edges.size() + g.carried_edges.size();
    u.ns = now_ns() - t0;
    return u;
  }
  std::size_t previous_n = 0;
  for (TaskId t = 0; t < n; ++t)
    if (const TaskId o = previous_task_.find(g.tasks[t].key); o != kNoTask) {
      old_of[t] = o;
      previous_n = std::max<std::size_t>(previous_n, o + 1);
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
          same = old_of[x.task] == y.task && x.mode() == y.mode() &&
                 (x.loop() == kNoLoop) == (y.loop() == kNoLoop) &&
                 (i == 0 || (x.loop() == nb[i - 1].loop()) == (y.loop() == ob[i - 1].loop()));
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
        thread_local detail::DatumState state, second_state;  // buffers kept between data
        detail::derive_datum(g, d, nb, ne, edges, carried, state, second_state);
        ++u.data_rederived;
      }
    }
    edge_begin[d + 1] = static_cast<std::uint32_t>(edges.size());
    carried_begin[d + 1] = static_cast<std::uint32_t>(carried.size());
  }
  detail::assemble_by_target(edges, n, g.edges);
  detail::assemble_by_target(carried, n, g.carried_edges);
  u.edges = g.edges.size() + g.carried_edges.size();
  remember(g, std::move(cur), keyed);
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
