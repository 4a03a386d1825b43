// SPDX-License-Identifier: MIT
// `list`: a critical-path list scheduler (HEFT-like) that also fixes the execution order.
#include <algorithm>
#include <cmath>
#include <queue>

#include "strategies.hpp"

namespace tgraph::partition::detail {

namespace {

/// Bottom-level priority list scheduling: tasks taken in decreasing bottom level (longest
/// path to a sink, communication included) as they become ready, each placed on the
/// processor where it finishes earliest (cost model's latency and per-byte cost for data
/// coming from another processor). Loop body tasks weigh cost x iterations; loop-carried
/// edges are ignored. The assignment carries the order in which each processor runs its
/// tasks: list start times, a loop's tasks kept together as one block.
class ListSchedule final : public Strategy {
 public:
  std::string_view name() const override { return "list"; }

 private:
  Result do_partition(const StepGraph& g, std::uint32_t k, const Previous&,
                      const Options& options) override {
    const auto n = static_cast<TaskId>(g.tasks.size());
    Result r;
    r.assignment.k = k;
    r.assignment.proc.assign(n, 0);
    if (k == 1 || n == 0) return r;

    const std::vector<std::uint64_t> work = task_work(g);
    std::vector<std::vector<std::pair<TaskId, double>>> succ(n), pred(n);
    for (const Edge& e : g.edges) {
      if (e.from == e.to) continue;
      double c = options.model.sync_latency_ns +
                 options.model.per_byte_ns * static_cast<double>(g.data[e.datum].bytes);
      const LoopId l = g.tasks[e.to].loop;
      if (l != kNoLoop && g.tasks[e.from].loop == l) c *= g.loops[l].iterations;
      succ[e.from].push_back({e.to, c});
      pred[e.to].push_back({e.from, c});
    }

    // Topological order (Kahn), then bottom levels in reverse.
    std::vector<std::uint32_t> indeg(n, 0);
    for (TaskId t = 0; t < n; ++t) indeg[t] = static_cast<std::uint32_t>(pred[t].size());
    std::vector<TaskId> topo;
    topo.reserve(n);
    for (TaskId t = 0; t < n; ++t)
      if (indeg[t] == 0) topo.push_back(t);
    for (std::size_t i = 0; i < topo.size(); ++i)
      for (const auto& [s, c] : succ[topo[i]])
        if (--indeg[s] == 0) topo.push_back(s);
    std::vector<double> bottom(n, 0.0);
    for (auto it = topo.rbegin(); it != topo.rend(); ++it) {
      double b = 0.0;
      for (const auto& [s, c] : succ[*it]) b = std::max(b, c + bottom[s]);
      bottom[*it] = b + static_cast<double>(work[*it]);
    }

    // Ready list by decreasing bottom level; earliest finish time placement.
    for (TaskId t = 0; t < n; ++t) indeg[t] = static_cast<std::uint32_t>(pred[t].size());
    auto lower = [&](TaskId a, TaskId b) {
      return bottom[a] != bottom[b] ? bottom[a] < bottom[b] : a > b;
    };
    std::priority_queue<TaskId, std::vector<TaskId>, decltype(lower)> ready(lower);
    for (TaskId t = 0; t < n; ++t)
      if (indeg[t] == 0) ready.push(t);
    std::vector<double> avail(k, 0.0), start(n, 0.0), finish(n, 0.0);
    std::vector<ProcId>& proc = r.assignment.proc;
    while (!ready.empty()) {
      const TaskId t = ready.top();
      ready.pop();
      ProcId best = 0;
      double best_start = 0.0, best_finish = INFINITY;
      for (ProcId p = 0; p < k; ++p) {
        double s = avail[p];
        for (const auto& [u, c] : pred[t]) s = std::max(s, finish[u] + (proc[u] == p ? 0.0 : c));
        const double f = s + static_cast<double>(work[t]);
        if (f < best_finish) {
          best = p;
          best_start = s;
          best_finish = f;
        }
      }
      proc[t] = best;
      start[t] = best_start;
      finish[t] = best_finish;
      avail[best] = best_finish;
      for (const auto& [s, c] : succ[t])
        if (--indeg[s] == 0) ready.push(s);
    }

    // Execution order: list start times, each loop contracted to one block (priority: its
    // earliest task) so that every processor's order stays consistent with one global
    // order and cannot deadlock. Within a block, start time order.
    const TaskId nodes = n + static_cast<TaskId>(g.loops.size());
    auto node_of = [&](TaskId t) { return g.tasks[t].loop == kNoLoop ? t : n + g.tasks[t].loop; };
    std::vector<double> prio(nodes, INFINITY);
    std::vector<TaskId> first(nodes, kNoTask);
    for (TaskId t = 0; t < n; ++t) {
      const TaskId v = node_of(t);
      prio[v] = std::min(prio[v], start[t]);
      first[v] = std::min(first[v], t);
    }
    std::vector<std::vector<TaskId>> nsucc(nodes);
    std::vector<std::uint32_t> nindeg(nodes, 0);
    for (const Edge& e : g.edges) {
      const TaskId a = node_of(e.from), b = node_of(e.to);
      if (a == b) continue;
      nsucc[a].push_back(b);
      ++nindeg[b];
    }
    auto later = [&](TaskId a, TaskId b) {
      return prio[a] != prio[b] ? prio[a] > prio[b] : first[a] > first[b];
    };
    std::priority_queue<TaskId, std::vector<TaskId>, decltype(later)> q(later);
    for (TaskId v = 0; v < nodes; ++v)
      if (first[v] != kNoTask && nindeg[v] == 0) q.push(v);
    std::vector<std::vector<TaskId>> body(g.loops.size());
    for (TaskId t = 0; t < n; ++t)
      if (g.tasks[t].loop != kNoLoop) body[g.tasks[t].loop].push_back(t);
    for (auto& b : body)
      std::sort(b.begin(), b.end(), [&](TaskId x, TaskId y) {
        return start[x] != start[y] ? start[x] < start[y] : x < y;
      });
    r.assignment.order.assign(k, {});
    while (!q.empty()) {
      const TaskId v = q.top();
      q.pop();
      if (v < n) {
        r.assignment.order[proc[v]].push_back(v);
      } else {
        for (TaskId t : body[v - n]) r.assignment.order[proc[t]].push_back(t);
      }
      for (TaskId s : nsucc[v])
        if (--nindeg[s] == 0) q.push(s);
    }
    std::size_t placed = 0;
    for (const auto& o : r.assignment.order) placed += o.size();
    if (placed != n) r.assignment.order.clear();  // cannot happen for forward edges
    return r;
  }
};

}  // namespace

std::unique_ptr<Strategy> make_list() { return std::make_unique<ListSchedule>(); }

}  // namespace tgraph::partition::detail
