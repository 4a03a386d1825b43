// SPDX-License-Identifier: MIT
#include "tgraph/graph/assignment.hpp"

#include <string>

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

}  // namespace tgraph
