// SPDX-License-Identifier: MIT
// Undirected, merged, symmetric CSR view of a step graph.
#include "tgraph/graph/undirected.hpp"

#include <algorithm>
#include <cmath>

namespace tgraph {
namespace {

void scale(std::vector<std::int64_t>& w, std::int64_t max_total) {
  if (max_total <= 0) return;
  long double total = 0;
  for (auto x : w) total += static_cast<long double>(x);
  if (total <= static_cast<long double>(max_total)) return;
  const long double f = static_cast<long double>(max_total) / total;
  for (auto& x : w) x = std::max<std::int64_t>(1, static_cast<std::int64_t>(std::llround(static_cast<long double>(x) * f)));
}

}  // namespace

UndirectedGraph make_undirected(const StepGraph& g, std::int64_t max_total_vertex_weight,
                                std::int64_t max_total_edge_weight) {
  const auto n = static_cast<std::uint32_t>(g.tasks.size());
  struct Half {
    std::uint32_t u, v;
    std::int64_t w;
  };
  std::vector<Half> halves;
  halves.reserve(2 * (g.edges.size() + g.carried_edges.size()));
  auto add = [&](const Edge& e) {
    if (e.from == e.to) return;
    const std::int64_t w = std::max<std::int64_t>(1, static_cast<std::int64_t>(g.data[e.datum].bytes));
    halves.push_back({e.from, e.to, w});
    halves.push_back({e.to, e.from, w});
  };
  for (const Edge& e : g.edges) add(e);
  for (const Edge& e : g.carried_edges) add(e);
  std::sort(halves.begin(), halves.end(), [](const Half& a, const Half& b) {
    return a.u != b.u ? a.u < b.u : a.v < b.v;
  });
  UndirectedGraph out;
  out.xadj.assign(n + 1, 0);
  for (std::size_t i = 0; i < halves.size();) {
    std::size_t j = i;
    std::int64_t w = 0;
    while (j < halves.size() && halves[j].u == halves[i].u && halves[j].v == halves[i].v) w += halves[j++].w;
    out.adjncy.push_back(halves[i].v);
    out.adjwgt.push_back(w);
    ++out.xadj[halves[i].u + 1];
    i = j;
  }
  for (std::uint32_t i = 0; i < n; ++i) out.xadj[i + 1] += out.xadj[i];
  out.vwgt.resize(n);
  for (TaskId t = 0; t < n; ++t)
    out.vwgt[t] = std::max<std::int64_t>(1, static_cast<std::int64_t>(g.tasks[t].cost_ns * g.runs(t)));
  scale(out.vwgt, max_total_vertex_weight);
  // Edge weights are scaled symmetrically: the same factor maps equal weights alike.
  if (max_total_edge_weight > 0) scale(out.adjwgt, 2 * max_total_edge_weight);
  return out;
}

}  // namespace tgraph
