// SPDX-License-Identifier: MIT
// `list`: a critical-path list scheduler (HEFT-like) that also fixes the execution order.
#include <algorithm>
#include <cmath>
#include <queue>

#include "strategies.hpp"

namespace tgraph::partition::detail {

namespace {

/// The step as a DAG for list scheduling: per-task work (loop bodies: cost x iterations),
/// edges with their communication estimate (a loop body's internal edges once per
/// iteration; loop-carried edges ignored), bottom levels (longest path to a sink,
/// communication included).
struct Dag {
  std::vector<std::uint64_t> work;
  std::vector<std::vector<std::pair<TaskId, double>>> succ, pred;
  std::vector<double> bottom;
};

Dag make_dag(const StepGraph& g, const model::CostModel& model) {
  const auto n = static_cast<TaskId>(g.tasks.size());
  Dag d;
  d.work = task_work(g);
  d.succ.assign(n, {});
  d.pred.assign(n, {});
  for (const Edge& e : g.edges) {
    if (e.from == e.to) continue;
    double c = model.sync_latency_ns + model.per_byte_ns * static_cast<double>(g.data[e.datum].bytes);
    const LoopId l = g.tasks[e.to].loop;
    if (l != kNoLoop && g.tasks[e.from].loop == l) c *= g.loops[l].iterations;
    d.succ[e.from].push_back({e.to, c});
    d.pred[e.to].push_back({e.from, c});
  }
  // Topological order (Kahn), then bottom levels in reverse.
  std::vector<std::uint32_t> indeg(n, 0);
  for (TaskId t = 0; t < n; ++t) indeg[t] = static_cast<std::uint32_t>(d.pred[t].size());
  std::vector<TaskId> topo;
  topo.reserve(n);
  for (TaskId t = 0; t < n; ++t)
    if (indeg[t] == 0) topo.push_back(t);
  for (std::size_t i = 0; i < topo.size(); ++i)
    for (const auto& [s, c] : d.succ[topo[i]])
      if (--indeg[s] == 0) topo.push_back(s);
  d.bottom.assign(n, 0.0);
  for (auto it = topo.rbegin(); it != topo.rend(); ++it) {
    double b = 0.0;
    for (const auto& [s, c] : d.succ[*it]) b = std::max(b, c + d.bottom[s]);
    d.bottom[*it] = b + static_cast<double>(d.work[*it]);
  }
  return d;
}

/// Higher bottom level first (ties: program order).
struct ByPriority {
  const std::vector<double>* bottom;
  bool operator()(TaskId a, TaskId b) const {
    const auto& bl = *bottom;
    return bl[a] != bl[b] ? bl[a] < bl[b] : a > b;
  }
};

/// Execution order from list start times: each loop contracted to one block (priority: its
/// earliest task) so that every processor's order stays consistent with one global order
/// and cannot deadlock. Within a block, start time order. Empty when the edges are not
/// forward (cannot happen for a derived step graph).
std::vector<std::vector<TaskId>> execution_order(const StepGraph& g, std::uint32_t k,
                                                 const std::vector<ProcId>& proc,
                                                 const std::vector<double>& start) {
  const auto n = static_cast<TaskId>(g.tasks.size());
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
  std::vector<std::vector<TaskId>> order(k);
  while (!q.empty()) {
    const TaskId v = q.top();
    q.pop();
    if (v < n) {
      order[proc[v]].push_back(v);
    } else {
      for (TaskId t : body[v - n]) order[proc[t]].push_back(t);
    }
    for (TaskId s : nsucc[v])
      if (--nindeg[s] == 0) q.push(s);
  }
  std::size_t placed = 0;
  for (const auto& o : order) placed += o.size();
  if (placed != n) order.clear();
  return order;
}

/// Bottom-level priority list scheduling: tasks taken in decreasing bottom level as they
/// become ready, each placed on the processor where it finishes earliest (cost model's
/// latency and per-byte cost for data coming from another processor). The assignment
/// carries the order in which each processor runs its tasks: list start times, a loop's
/// tasks kept together as one block.
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
    const Dag d = make_dag(g, options.model);
    std::vector<std::uint32_t> indeg(n, 0);
    for (TaskId t = 0; t < n; ++t) indeg[t] = static_cast<std::uint32_t>(d.pred[t].size());
    std::priority_queue<TaskId, std::vector<TaskId>, ByPriority> ready(ByPriority{&d.bottom});
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
        for (const auto& [u, c] : d.pred[t]) s = std::max(s, finish[u] + (proc[u] == p ? 0.0 : c));
        const double f = s + static_cast<double>(d.work[t]);
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
      for (const auto& [s, c] : d.succ[t])
        if (--indeg[s] == 0) ready.push(s);
    }
    r.assignment.order = execution_order(g, k, proc, start);
    return r;
  }
};

}  // namespace

std::unique_ptr<Strategy> make_list() { return std::make_unique<ListSchedule>(); }

std::vector<std::vector<TaskId>> list_order(const StepGraph& g, const Assignment& a,
                                            const model::CostModel& model) {
  const auto n = static_cast<TaskId>(g.tasks.size());
  const std::uint32_t k = a.k;
  if (k <= 1 || n == 0) return {};
  const Dag d = make_dag(g, model);
  // Event-driven: at time `now` each idle processor starts, of its tasks whose
  // predecessors have all finished and whose data has arrived, the one of highest bottom
  // level; a task's data arrives at its predecessors' finish (plus the cost model's
  // communication from another processor).
  std::vector<std::uint32_t> indeg(n, 0);
  for (TaskId t = 0; t < n; ++t) indeg[t] = static_cast<std::uint32_t>(d.pred[t].size());
  std::vector<double> arrival(n, 0.0), start(n, 0.0);
  using Timed = std::pair<double, TaskId>;
  std::vector<std::priority_queue<Timed, std::vector<Timed>, std::greater<>>> pending(k);
  std::vector<std::priority_queue<TaskId, std::vector<TaskId>, ByPriority>> ready(
      k, std::priority_queue<TaskId, std::vector<TaskId>, ByPriority>(ByPriority{&d.bottom}));
  std::vector<bool> busy(k, false);
  std::priority_queue<Timed, std::vector<Timed>, std::greater<>> events;  // (time, task ended)
  for (TaskId t = 0; t < n; ++t)
    if (indeg[t] == 0) pending[a.proc[t]].push({0.0, t});
  double now = 0.0;
  TaskId done = 0;
  while (done < n) {
    double wake = INFINITY;
    for (ProcId p = 0; p < k; ++p) {
      while (!pending[p].empty() && pending[p].top().first <= now) {
        ready[p].push(pending[p].top().second);
        pending[p].pop();
      }
      if (busy[p]) continue;
      if (!ready[p].empty()) {
        const TaskId t = ready[p].top();
        ready[p].pop();
        busy[p] = true;
        start[t] = now;
        events.push({now + static_cast<double>(d.work[t]), t});
      } else if (!pending[p].empty()) {
        wake = std::min(wake, pending[p].top().first);
      }
    }
    if (events.empty() && wake == INFINITY) return {};  // cannot happen for a DAG
    if (!events.empty() && events.top().first <= wake) {
      const auto [time, t] = events.top();
      events.pop();
      now = time;
      busy[a.proc[t]] = false;
      ++done;
      for (const auto& [s, c] : d.succ[t]) {
        arrival[s] = std::max(arrival[s], time + (a.proc[s] == a.proc[t] ? 0.0 : c));
        if (--indeg[s] == 0) pending[a.proc[s]].push({arrival[s], s});
      }
    } else {
      now = wake;
    }
  }
  return execution_order(g, k, a.proc, start);
}

}  // namespace tgraph::partition::detail
