// SPDX-License-Identifier: MIT
// Work, span (loops unrolled) and parallelism.
#include "tgraph/graph/metrics.hpp"

#include <algorithm>
#include <utility>

namespace tgraph {
namespace {

// Predecessor lists in CSR form: from[begin[t]..begin[t + 1]) are the sources of t's edges.
struct Preds {
  std::vector<std::uint32_t> begin;
  std::vector<TaskId> from;
};

Preds build_preds(std::size_t n, const std::vector<Edge>& edges) {
  IncomingEdges in = incoming_edges(n, edges);
  Preds p{std::move(in.begin), std::move(in.edge)};
  for (TaskId& f : p.from) f = edges[f].from;
  return p;
}

}  // namespace

IncomingEdges incoming_edges(std::size_t tasks, const std::vector<Edge>& edges) {
  IncomingEdges in;
  in.begin.assign(tasks + 1, 0);
  for (const Edge& e : edges) ++in.begin[e.to + 1];
  for (std::size_t i = 0; i < tasks; ++i) in.begin[i + 1] += in.begin[i];
  in.edge.resize(edges.size());
  std::vector<std::uint32_t> fill(in.begin.begin(), in.begin.end() - 1);
  for (std::uint32_t i = 0; i < edges.size(); ++i) in.edge[fill[edges[i].to]++] = i;
  return in;
}

std::vector<std::uint64_t> earliest_finish(const StepGraph& g) {
  const std::size_t n = g.tasks.size();
  const Preds intra = build_preds(n, g.edges);
  const Preds carried = build_preds(n, g.carried_edges);
  std::vector<std::uint64_t> finish(n, 0);
  std::vector<std::uint64_t> prev;  // finish times of the previous iteration (loop body)

  auto run = [&](TaskId t, std::uint64_t gate, bool use_carried) {
    std::uint64_t start = gate;
    for (auto i = intra.begin[t]; i < intra.begin[t + 1]; ++i) start = std::max(start, finish[intra.from[i]]);
    if (use_carried)
      for (auto i = carried.begin[t]; i < carried.begin[t + 1]; ++i)
        start = std::max(start, prev[carried.from[i]]);
    finish[t] = start + g.tasks[t].cost_ns;
  };

  std::size_t next_loop = 0;
  for (TaskId t = 0; t < n;) {
    if (next_loop < g.loops.size() && g.loops[next_loop].first == t) {
      const Loop& loop = g.loops[next_loop++];
      std::uint64_t gate = 0;
      // Indexed by task id, read for the body's tasks only: sized once, not cleared per loop
      // (a loop's carried edges come from its own body, written before they are read).
      if (prev.size() != n) prev.assign(n, 0);
      for (std::uint32_t it = 0; it < loop.iterations; ++it) {
        if (it > 0) {
          std::copy(finish.begin() + loop.first, finish.begin() + loop.last, prev.begin() + loop.first);
          gate = finish[loop.last - 1];  // the conditional break of the previous iteration
        }
        for (TaskId u = loop.first; u < loop.last; ++u) run(u, gate, it > 0);
      }
      t = loop.last;
      continue;
    }
    run(t, 0, false);
    ++t;
  }
  return finish;
}

Metrics compute_metrics(const StepGraph& g) {
  Metrics m;
  m.tasks = g.tasks.size();
  m.edges = g.edges.size() + g.carried_edges.size();
  m.data = g.data.size();
  m.loops = g.loops.size();
  for (const Loop& l : g.loops) m.loop_iterations += l.iterations;
  std::vector<std::uint64_t> per_kind(g.kinds.size(), 0);  // by kind id, named once below
  for (TaskId t = 0; t < g.tasks.size(); ++t) {
    m.work_ns += g.tasks[t].cost_ns * g.runs(t);
    ++per_kind[g.tasks[t].kind];
  }
  for (KindId k = 0; k < per_kind.size(); ++k)
    if (per_kind[k] != 0) m.per_kind[g.kinds[k]] += per_kind[k];
  const auto finish = earliest_finish(g);
  for (auto f : finish) m.span_ns = std::max(m.span_ns, f);
  m.parallelism = m.span_ns == 0 ? 0.0 : static_cast<double>(m.work_ns) / static_cast<double>(m.span_ns);
  return m;
}

UnitMetrics compute_unit_metrics(const StepGraph& g) {
  StepGraph unit = g;
  for (Task& t : unit.tasks) t.cost_ns = 1;
  UnitMetrics m;
  for (TaskId t = 0; t < g.tasks.size(); ++t) m.work_tasks += g.runs(t);
  for (const std::uint64_t f : earliest_finish(unit)) m.span_tasks = std::max(m.span_tasks, f);
  m.parallelism = m.span_tasks == 0 ? 0.0
                                    : static_cast<double>(m.work_tasks) /
                                          static_cast<double>(m.span_tasks);
  return m;
}

std::vector<std::vector<std::uint64_t>> robust_costs(const std::vector<StepGraph>& steps) {
  // Steps grouped by structure: the hash first, same_structure to confirm.
  std::vector<std::vector<std::size_t>> groups;
  std::vector<std::uint64_t> hashes;
  for (std::size_t i = 0; i < steps.size(); ++i) {
    const std::uint64_t h = steps[i].structural_hash();
    std::size_t g = 0;
    while (g < groups.size() &&
           !(hashes[g] == h && steps[groups[g].front()].same_structure(steps[i])))
      ++g;
    if (g == groups.size()) {
      groups.emplace_back();
      hashes.push_back(h);
    }
    groups[g].push_back(i);
  }
  std::vector<std::vector<std::uint64_t>> out(steps.size());
  std::vector<std::uint64_t> costs;
  for (const std::vector<std::size_t>& members : groups) {
    const std::size_t n = steps[members.front()].tasks.size();
    std::vector<std::uint64_t> median(n);
    for (std::size_t t = 0; t < n; ++t) {
      costs.clear();
      for (const std::size_t i : members) costs.push_back(steps[i].tasks[t].cost_ns);
      // The lower median of an even count: a cost that was measured, not an average.
      const auto mid = costs.begin() + static_cast<std::ptrdiff_t>((costs.size() - 1) / 2);
      std::nth_element(costs.begin(), mid, costs.end());
      median[t] = *mid;
    }
    for (const std::size_t i : members) out[i] = median;
  }
  return out;
}

}  // namespace tgraph
