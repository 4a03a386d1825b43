// SPDX-License-Identifier: MIT
#include "schedule_program.hpp"

#include <cstdint>
#include <string>

namespace tgraph::model {

namespace detail {

std::vector<std::uint64_t> first_instances(const StepGraph& g) {
  const auto n = static_cast<TaskId>(g.tasks.size());
  std::vector<std::uint64_t> first(n + 1);
  std::uint64_t total = 0;
  for (TaskId t = 0; t < n; ++t) {
    first[t] = total;
    total += g.runs(t);
  }
  first[n] = total;
  return first;
}

std::vector<std::vector<Dep>> dependencies(const StepGraph& g) {
  std::vector<std::vector<Dep>> deps(g.tasks.size());
  for (const Edge& e : g.edges)
    if (e.from != e.to) deps[e.to].push_back({e.from, e.datum, e.kind == EdgeKind::RAW, false});
  for (const Edge& e : g.carried_edges)
    deps[e.to].push_back({e.from, e.datum, e.kind == EdgeKind::RAW, true});
  return deps;
}

std::vector<std::vector<Item>> programs(const StepGraph& g, const Assignment& a) {
  const auto n = static_cast<TaskId>(g.tasks.size());
  std::vector<std::vector<Item>> items(a.k);
  std::vector<std::vector<std::size_t>> block(a.k,
                                              std::vector<std::size_t>(g.loops.size(), SIZE_MAX));
  auto place = [&](ProcId p, TaskId t) {
    const LoopId l = g.tasks[t].loop;
    if (l == kNoLoop) {
      items[p].push_back({t, kNoLoop, {}});
      return;
    }
    if (block[p][l] == SIZE_MAX) {
      block[p][l] = items[p].size();
      items[p].push_back({kNoTask, l, {}});
    }
    items[p][block[p][l]].body.push_back(t);
  };
  if (a.order.empty()) {
    for (TaskId t = 0; t < n; ++t) place(a.proc[t], t);
  } else {
    for (ProcId p = 0; p < a.k; ++p)
      for (TaskId t : a.order[p]) place(p, t);
  }
  return items;
}

std::string deadlock_message(const StepGraph& g, const Item& it, std::size_t pos, ProcId p) {
  const TaskId t = it.task != kNoTask     ? it.task
                   : pos < it.body.size() ? it.body[pos]
                                          : g.loops[it.loop].last - 1;
  return "assignment order deadlocks: processor " + std::to_string(p) +
         " waits forever before task " + std::to_string(t);
}

}  // namespace detail

}  // namespace tgraph::model
