// SPDX-License-Identifier: MIT
// Instance-level longest path, with the same unrolling rules as libgraph's earliest_finish():
// iteration i+1 of a loop starts after iteration i's conditional break, loop-carried edges
// link iteration i to i+1, edges into a loop feed iteration 0's instances from the producer's
// last run, edges out of a loop read its last iteration.
#include "tgraph/viz/critical_path.hpp"

#include <algorithm>
#include <limits>

#include "tgraph/graph/metrics.hpp"

namespace tgraph::viz {
namespace {

constexpr std::uint64_t kNone = std::numeric_limits<std::uint64_t>::max();

struct Origin {
  std::uint64_t from = kNone;  // predecessor instance
  PathLink link = PathLink::kStart;
  std::uint32_t edge = 0;
};

}  // namespace

const char* to_string(PathLink link) {
  switch (link) {
    case PathLink::kStart:
      return "start";
    case PathLink::kEdge:
      return "edge";
    case PathLink::kCarried:
      return "carried";
    case PathLink::kLoopGate:
      return "loop gate";
  }
  return "?";
}

CriticalPath critical_path(const StepGraph& g) {
  const std::size_t n = g.tasks.size();
  CriticalPath cp;
  cp.task_hits.assign(n, 0);
  cp.edge_hits.assign(g.edges.size(), 0);
  cp.carried_hits.assign(g.carried_edges.size(), 0);
  if (n == 0) return cp;

  std::vector<std::uint64_t> first(n + 1, 0);
  for (TaskId t = 0; t < n; ++t) first[t + 1] = first[t] + g.runs(t);
  const std::uint64_t instances = first[n];
  std::vector<std::uint64_t> finish(instances, 0);
  std::vector<Origin> origin(instances);
  const IncomingEdges intra = incoming_edges(n, g.edges);
  const IncomingEdges carried = incoming_edges(n, g.carried_edges);

  // Instance of `from` that an intra edge into iteration `it` of `to` reads.
  auto source = [&](TaskId from, TaskId to, std::uint32_t it) -> std::uint64_t {
    const std::uint64_t runs = g.runs(from);
    if (runs == 0) return kNone;
    const LoopId lf = g.tasks[from].loop;
    if (lf != kNoLoop && lf == g.tasks[to].loop) return first[from] + it;
    return first[from] + runs - 1;
  };

  auto run = [&](TaskId t, std::uint32_t it, std::uint64_t gate_instance) {
    std::uint64_t start = 0;
    Origin best;
    if (gate_instance != kNone) {
      start = finish[gate_instance];
      best = {gate_instance, PathLink::kLoopGate, 0};
    }
    // A predecessor replaces the current one only when strictly later: ties keep the loop
    // gate, then the first edge found.
    auto consider = [&](std::uint64_t inst, PathLink link, std::uint32_t edge) {
      if (inst == kNone) return;
      if (best.from == kNone || finish[inst] > start) {
        start = std::max(start, finish[inst]);
        best = {inst, link, edge};
      }
    };
    for (auto i = intra.begin[t]; i < intra.begin[t + 1]; ++i) {
      const std::uint32_t e = intra.edge[i];
      consider(source(g.edges[e].from, t, it), PathLink::kEdge, e);
    }
    if (it > 0)
      for (auto i = carried.begin[t]; i < carried.begin[t + 1]; ++i) {
        const std::uint32_t e = carried.edge[i];
        consider(first[g.carried_edges[e].from] + it - 1, PathLink::kCarried, e);
      }
    const std::uint64_t self = first[t] + it;
    finish[self] = start + g.tasks[t].cost_ns;
    origin[self] = best;
  };

  std::size_t next_loop = 0;
  for (TaskId t = 0; t < n;) {
    if (next_loop < g.loops.size() && g.loops[next_loop].first == t) {
      const Loop& loop = g.loops[next_loop++];
      for (std::uint32_t it = 0; it < loop.iterations; ++it) {
        const std::uint64_t gate = it == 0 ? kNone : first[loop.last - 1] + it - 1;
        for (TaskId u = loop.first; u < loop.last; ++u) run(u, it, gate);
      }
      t = loop.last;
      continue;
    }
    run(t, 0, kNone);
    ++t;
  }

  std::uint64_t end = kNone;
  for (std::uint64_t i = 0; i < instances; ++i)
    if (end == kNone || finish[i] > finish[end]) end = i;
  if (end == kNone) return cp;
  cp.length_ns = finish[end];

  // Instance index -> (task, iteration).
  auto task_of = [&](std::uint64_t inst) {
    const auto it = std::upper_bound(first.begin(), first.end(), inst);
    const auto t = static_cast<TaskId>(it - first.begin() - 1);
    return TaskInstance{t, static_cast<std::uint32_t>(inst - first[t])};
  };
  for (std::uint64_t i = end; i != kNone; i = origin[i].from) {
    cp.instances.push_back(task_of(i));
    cp.links.push_back(origin[i].link);
    cp.edge_of.push_back(origin[i].edge);
  }
  std::reverse(cp.instances.begin(), cp.instances.end());
  std::reverse(cp.links.begin(), cp.links.end());
  std::reverse(cp.edge_of.begin(), cp.edge_of.end());
  for (std::size_t i = 0; i < cp.instances.size(); ++i) {
    ++cp.task_hits[cp.instances[i].task];
    if (cp.links[i] == PathLink::kEdge) ++cp.edge_hits[cp.edge_of[i]];
    if (cp.links[i] == PathLink::kCarried) ++cp.carried_hits[cp.edge_of[i]];
  }
  return cp;
}

}  // namespace tgraph::viz
