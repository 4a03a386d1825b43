// SPDX-License-Identifier: MIT
#include "tgraph/partition/partition_graph.hpp"

#include <algorithm>

#include "strategies.hpp"

namespace tgraph::partition {

UndirectedGraph library_graph(const StepGraph& g) {
  return make_undirected(g, kMaxLibraryWeight, kMaxLibraryWeight);
}

LibraryWeights library_weights(const UndirectedGraph& u, const std::vector<std::uint32_t>& phase,
                               std::uint32_t nphases) {
  LibraryWeights w;
  const std::uint32_t n = u.vertices();
  const bool multi = phase.size() == n && nphases > 1;
  w.ncon = multi ? nphases : 1;
  w.vwgt.assign(static_cast<std::size_t>(n) * w.ncon, 0);
  for (std::uint32_t v = 0; v < n; ++v) {
    const std::uint32_t c = multi ? phase[v] : 0;
    w.vwgt[static_cast<std::size_t>(v) * w.ncon + c] =
        static_cast<std::int32_t>(std::clamp<std::int64_t>(u.vwgt[v], 1, kMaxLibraryWeight));
  }
  w.adjwgt.resize(u.adjwgt.size());
  for (std::size_t i = 0; i < u.adjwgt.size(); ++i)
    w.adjwgt[i] = static_cast<std::int32_t>(std::clamp<std::int64_t>(u.adjwgt[i], 1, kMaxLibraryWeight));
  return w;
}

std::vector<std::uint32_t> task_levels(const StepGraph& g) {
  std::vector<std::uint32_t> level(g.tasks.size(), 0);
  // Intra-step edges go forward in program order: relax them by increasing source.
  std::vector<Edge> edges = g.edges;
  std::sort(edges.begin(), edges.end(), [](const Edge& a, const Edge& b) {
    return a.from != b.from ? a.from < b.from : a.to < b.to;
  });
  for (const Edge& e : edges)
    if (e.from < e.to && e.to < level.size()) level[e.to] = std::max(level[e.to], level[e.from] + 1);
  return level;
}

namespace {
// A task's work in a step: its cost times its executions (at least 1).
std::uint64_t task_work(const StepGraph& g, TaskId t) {
  return std::max<std::uint64_t>(1, g.tasks[t].cost_ns * g.runs(t));
}
}  // namespace

std::vector<std::uint32_t> task_phases(const StepGraph& g, std::uint32_t nphases,
                                       std::uint32_t& used, double loop_share,
                                       std::uint32_t rest_phases) {
  return task_phases(g, task_levels(g), nphases, used, loop_share, rest_phases);
}

std::vector<std::uint32_t> task_phases(const StepGraph& g, const std::vector<std::uint32_t>& level,
                                       std::uint32_t nphases, std::uint32_t& used,
                                       double loop_share, std::uint32_t rest_phases) {
  used = 0;
  if (level.empty()) return {};
  nphases = std::max<std::uint32_t>(nphases, 1);
  const std::size_t n = g.tasks.size();
  std::vector<std::uint64_t> weight(n);
  for (TaskId t = 0; t < n; ++t) weight[t] = task_work(g, t);
  // Groups: 0 the tasks outside heavy loops, then one per heavy loop in loop order.
  const detail::LoopGroups lg = detail::loop_groups(g, weight, loop_share);
  const std::vector<std::uint32_t>& group = lg.group;
  const std::uint32_t groups = lg.count;
  if (groups > 1 && rest_phases > 0) nphases = rest_phases;
  // Group 0: level l goes to the phase holding the middle of its work in the cumulative
  // order. A heavy loop is one phase (nphases - 1 + its group): cutting it by levels too
  // gives METIS more constraints than it balances on a small step (torso at K = 8: 6
  // constraints, imbalance 4.1; docs/partitioning.md).
  const std::uint32_t nlevels = *std::max_element(level.begin(), level.end()) + 1;
  std::vector<std::uint64_t> work(nlevels, 0);  // group 0's, by level
  std::uint64_t rest = 0;                        // group 0's in all
  for (TaskId t = 0; t < n; ++t)
    if (group[t] == 0) {
      work[level[t]] += weight[t];
      rest += weight[t];
    }
  std::vector<std::uint32_t> phase_of_level(nlevels, 0);
  std::uint64_t before = 0;
  for (std::uint32_t l = 0; l < nlevels && rest > 0; ++l) {
    const long double mid = static_cast<long double>(before) + static_cast<long double>(work[l]) / 2;
    const auto p = static_cast<std::uint32_t>(mid * nphases / static_cast<long double>(rest));
    phase_of_level[l] = std::min(p, nphases - 1);
    before += work[l];
  }
  std::vector<std::uint32_t> phase(n);
  for (TaskId t = 0; t < n; ++t)
    phase[t] = group[t] == 0 ? phase_of_level[level[t]] : nphases - 1 + group[t];
  // Dense numbering of the non-empty phases, in phase order.
  std::vector<bool> seen(nphases - 1 + groups, false);
  for (const std::uint32_t p : phase) seen[p] = true;
  std::vector<std::uint32_t> dense(seen.size(), 0);
  for (std::uint32_t p = 0; p < seen.size(); ++p)
    if (seen[p]) dense[p] = used++;
  for (std::uint32_t& p : phase) p = dense[p];
  return phase;
}

std::int64_t edgecut(const UndirectedGraph& u, const std::vector<std::uint32_t>& part) {
  std::int64_t cut = 0;
  for (std::uint32_t v = 0; v < u.vertices(); ++v)
    for (std::uint32_t i = u.xadj[v]; i < u.xadj[v + 1]; ++i)
      if (u.adjncy[i] > v && part[v] != part[u.adjncy[i]]) cut += u.adjwgt[i];
  return cut;
}

}  // namespace tgraph::partition
