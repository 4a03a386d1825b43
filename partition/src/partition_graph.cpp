// SPDX-License-Identifier: MIT
#include "tgraph/partition/partition_graph.hpp"

#include <algorithm>

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

std::vector<std::uint32_t> task_phases(const StepGraph& g, std::uint32_t nphases,
                                       std::uint32_t& used) {
  const std::vector<std::uint32_t> level = task_levels(g);
  used = 0;
  if (level.empty()) return {};
  nphases = std::max<std::uint32_t>(nphases, 1);
  const std::uint32_t nlevels = *std::max_element(level.begin(), level.end()) + 1;
  std::vector<std::uint64_t> work(nlevels, 0);
  std::uint64_t total = 0;
  for (TaskId t = 0; t < g.tasks.size(); ++t) {
    const std::uint64_t w = std::max<std::uint64_t>(1, g.tasks[t].cost_ns * g.runs(t));
    work[level[t]] += w;
    total += w;
  }
  // Level l goes to the phase holding the middle of its work in the cumulative order.
  std::vector<std::uint32_t> phase_of_level(nlevels, 0);
  std::uint64_t before = 0;
  for (std::uint32_t l = 0; l < nlevels; ++l) {
    const long double mid = static_cast<long double>(before) + static_cast<long double>(work[l]) / 2;
    const auto p = static_cast<std::uint32_t>(mid * nphases / static_cast<long double>(total));
    phase_of_level[l] = std::min(p, nphases - 1);
    before += work[l];
  }
  std::vector<std::uint32_t> dense(nphases, 0);
  std::vector<bool> seen(nphases, false);
  for (std::uint32_t l = 0; l < nlevels; ++l)
    if (work[l] > 0) seen[phase_of_level[l]] = true;
  for (std::uint32_t p = 0; p < nphases; ++p)
    if (seen[p]) dense[p] = used++;
  std::vector<std::uint32_t> phase(g.tasks.size());
  for (TaskId t = 0; t < g.tasks.size(); ++t) phase[t] = dense[phase_of_level[level[t]]];
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
