// SPDX-License-Identifier: MIT
#include "tgraph/graph/assignment.hpp"

#include <map>
#include <string>
#include <utility>

namespace tgraph {

std::string validate(const StepGraph& g, const Assignment& a, std::uint32_t k) {
  if (k == 0) return "k must be at least 1";
  if (a.k != k)
    return "assignment has k = " + std::to_string(a.k) + ", expected " + std::to_string(k);
  if (a.proc.size() != g.tasks.size())
    return "assignment covers " + std::to_string(a.proc.size()) + " tasks, the step has " +
           std::to_string(g.tasks.size());
  for (TaskId t = 0; t < a.proc.size(); ++t)
    if (a.proc[t] >= k)
      return "assignment puts task " + std::to_string(t) + " on processor " +
             std::to_string(a.proc[t]) + " >= k = " + std::to_string(k);
  if (a.order.empty()) return {};
  if (a.order.size() != k)
    return "assignment order has " + std::to_string(a.order.size()) +
           " processors, k = " + std::to_string(k);
  std::vector<bool> seen(g.tasks.size(), false);
  std::size_t listed = 0;
  for (ProcId p = 0; p < k; ++p)
    for (TaskId t : a.order[p]) {
      if (t >= g.tasks.size())
        return "assignment order of processor " + std::to_string(p) + " lists task " +
               std::to_string(t) + ", the step has " + std::to_string(g.tasks.size());
      if (a.proc[t] != p)
        return "assignment order of processor " + std::to_string(p) + " lists task " +
               std::to_string(t) + ", which is on processor " + std::to_string(a.proc[t]);
      if (seen[t])
        return "assignment order of processor " + std::to_string(p) + " lists task " +
               std::to_string(t) + " twice";
      seen[t] = true;
      ++listed;
    }
  if (listed != g.tasks.size())
    return "assignment order lists " + std::to_string(listed) + " of " +
           std::to_string(g.tasks.size()) + " tasks";
  return {};
}

QuotientGraph quotient_graph(const StepGraph& g, const Assignment& a) {
  QuotientGraph q;
  q.load_ns.assign(a.k, 0);
  q.tasks.assign(a.k, 0);
  for (TaskId t = 0; t < g.tasks.size(); ++t) {
    q.load_ns[a.proc[t]] += g.tasks[t].cost_ns * g.runs(t);
    ++q.tasks[a.proc[t]];
  }
  std::map<std::pair<ProcId, ProcId>, QuotientEdge> pairs;  // ordered: edges come out sorted
  auto cut = [&](const Edge& e, bool carried) {
    const ProcId from = a.proc[e.from], to = a.proc[e.to];
    if (from == to) return;
    QuotientEdge& qe = pairs.try_emplace({from, to}, QuotientEdge{from, to}).first->second;
    ++(carried ? qe.carried_deps : qe.deps);
    qe.bytes += g.data[e.datum].bytes;
  };
  for (const Edge& e : g.edges) cut(e, false);
  for (const Edge& e : g.carried_edges) cut(e, true);
  for (const auto& [pair, qe] : pairs) q.edges.push_back(qe);
  return q;
}

}  // namespace tgraph
