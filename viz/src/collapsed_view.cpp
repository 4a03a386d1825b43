// SPDX-License-Identifier: MIT
// The aggregated picture of a step (Collapse::kObject, kKind, kProcessor or kLoop): one node per
// group of tasks, edges summed between groups.
#include <algorithm>
#include <map>
#include <set>
#include <tuple>

#include "graph_view_builders.hpp"

namespace tgraph::viz::detail {
namespace {

std::uint64_t iterations_of(const StepGraph& g, LoopId l) {
  return l == kNoLoop ? 1 : g.loops[l].iterations;
}

}  // namespace

void build_collapsed_view(const StepGraph& g, const ViewOptions& o, const CriticalPath* cp,
                          GraphView& v) {
  const Assignment* a = o.assignment;
  std::map<std::pair<std::string, LoopId>, std::uint32_t> index;
  std::vector<std::uint32_t> node_of(g.tasks.size());
  std::vector<std::map<ProcId, std::uint64_t>> shares;
  std::vector<std::string> names;
  std::vector<LoopId> body;  // Collapse::kLoop: the loop a node stands for
  std::uint32_t region = 0;  // loops that ended before task t
  for (TaskId t = 0; t < g.tasks.size(); ++t) {
    const Task& task = g.tasks[t];
    std::string key, name;
    LoopId loop = task.loop;
    bool single = false;
    switch (o.collapse) {
      case Collapse::kObject:
        if (task.object != kNoObject) {
          key = "o" + std::to_string(task.object);
          name = g.objects[task.object].name;
        } else {
          key = "k" + std::to_string(task.kind);
          name = g.kinds[task.kind] + " (shared)";
        }
        break;
      case Collapse::kKind:
        key = "k" + std::to_string(task.kind);
        name = g.kinds[task.kind];
        break;
      case Collapse::kProcessor:
        key = "p" + std::to_string(a->proc[t]);
        name = "p" + std::to_string(a->proc[t]);
        break;
      case Collapse::kLoop:
        if (task.loop != kNoLoop) {
          key = "L" + std::to_string(task.loop);
          name = "loop " + std::to_string(task.loop);
        } else {
          key = "t" + std::to_string(t);
          name = g.kind_name(t);
          single = true;
        }
        loop = kNoLoop;  // the loop is the node itself
        break;
      case Collapse::kNone:
        break;
    }
    // Outside loops, tasks are grouped by the region they run in (before loop 0, after loop
    // 0, ...): one node for an object's tasks before and after a loop would form a cycle
    // with its loop node, which dot draws as long arcs across the picture.
    while (region < g.loops.size() && g.loops[region].last <= t) ++region;
    if (loop == kNoLoop && o.collapse != Collapse::kLoop && !g.loops.empty()) {
      key += "r" + std::to_string(region);
      name += region == 0 ? std::string("\nbefore loop 0")
                          : "\nafter loop " + std::to_string(region - 1);
    }
    auto [it, fresh] = index.try_emplace({key, loop}, static_cast<std::uint32_t>(v.nodes.size()));
    if (fresh) {
      ViewNode n;
      n.id = "g" + std::to_string(v.nodes.size());
      n.kind = single ? NodeKind::kTask : NodeKind::kGroup;
      n.loop = loop;
      v.nodes.push_back(std::move(n));
      shares.emplace_back();
      body.push_back(single ? kNoLoop : task.loop);
      names.push_back(single && task.object != kNoObject ? name + "\n" + g.objects[task.object].name
                                                         : name);
    }
    const std::uint32_t k = it->second;
    node_of[t] = k;
    ViewNode& n = v.nodes[k];
    const std::uint64_t work = task.cost_ns * g.runs(t);
    ++n.tasks;
    n.work_ns += work;
    if (cp) n.critical_hits += cp->task_hits[t];
    if (a) shares[k][a->proc[t]] += work;
  }
  // Labels once the totals are known.
  for (std::uint32_t k = 0; k < v.nodes.size(); ++k) {
    ViewNode& n = v.nodes[k];
    std::string first = names[k], rest;
    if (const auto nl = first.find('\n'); nl != std::string::npos) {
      rest = first.substr(nl + 1);
      first.resize(nl);
    }
    n.lines.push_back(first);
    if (!rest.empty()) n.lines.push_back(rest);
    const bool loop_node = o.collapse == Collapse::kLoop && n.kind == NodeKind::kGroup;
    if (n.kind == NodeKind::kGroup) {
      std::string count = std::to_string(n.tasks) + (n.tasks == 1 ? " task" : " tasks");
      const LoopId l = loop_node ? body[k] : n.loop;
      if (l != kNoLoop) count += " \xC3\x97 " + std::to_string(iterations_of(g, l)) + " it.";
      n.lines.push_back(count);
    }
    n.lines.push_back("work " + format_ns(static_cast<double>(n.work_ns)));
    for (const auto& [p, w] : shares[k]) n.procs.push_back({p, w});
    if (n.procs.size() == 1) {
      n.lines.back() = "p" + std::to_string(n.procs.front().proc) + " \xC2\xB7 " + n.lines.back();
    } else if (n.procs.size() > 1) {
      std::vector<ProcessorShare> by_work = n.procs;
      std::stable_sort(
          by_work.begin(), by_work.end(),
          [](const ProcessorShare& x, const ProcessorShare& y) { return x.work_ns > y.work_ns; });
      std::string mix;
      for (std::size_t i = 0; i < by_work.size() && i < 3; ++i) {
        const double pct = n.work_ns == 0 ? 0.0
                                          : 100.0 * static_cast<double>(by_work[i].work_ns) /
                                                static_cast<double>(n.work_ns);
        mix += (i ? " \xC2\xB7 " : "") + ("p" + std::to_string(by_work[i].proc)) + " " + sig3(pct) +
               "%";
      }
      if (by_work.size() > 3) mix += " \xC2\xB7 +" + std::to_string(by_work.size() - 3);
      n.lines.push_back(mix);
    }
  }
  // Aggregated edges: dependencies between different nodes, bytes per step. Targets that
  // depend on the same two or more sources through one datum (readers of a CW sum, writers
  // after a round of readers) meet at one datum node, so that n x m dependencies between
  // aggregates draw as n + m edges.
  struct Item {
    TaskId from, to;
    DatumId datum;
    EdgeKind kind;
    bool carried;
    std::uint32_t critical;
  };
  std::vector<Item> items;
  for (std::size_t i = 0; i < g.edges.size(); ++i) {
    const Edge& e = g.edges[i];
    items.push_back({e.from, e.to, e.datum, e.kind, false, cp ? cp->edge_hits[i] : 0});
  }
  for (std::size_t i = 0; i < g.carried_edges.size(); ++i) {
    const Edge& e = g.carried_edges[i];
    items.push_back({e.from, e.to, e.datum, e.kind, true, cp ? cp->carried_hits[i] : 0});
  }
  using Target = std::tuple<DatumId, int, bool, TaskId>;  // datum, kind, carried, reader
  std::map<Target, std::vector<TaskId>> sources;
  for (const Item& it : items)
    sources[{it.datum, static_cast<int>(it.kind), it.carried, it.to}].push_back(it.from);
  std::map<std::tuple<DatumId, int, bool, std::vector<TaskId>>, std::vector<TaskId>> sharing;
  for (auto& [t, src] : sources) {
    if (src.size() < 2) continue;
    std::sort(src.begin(), src.end());
    sharing[{std::get<0>(t), std::get<1>(t), std::get<2>(t), src}].push_back(std::get<3>(t));
  }
  std::map<Target, std::uint32_t> hub_of;
  for (const auto& [key, targets] : sharing) {
    if (targets.size() < 2) continue;
    const auto& [datum, kind, carried, src] = key;
    // The hub sits in a loop cluster when every end does.
    LoopId loop = v.nodes[node_of[src.front()]].loop;
    for (TaskId t : src) loop = v.nodes[node_of[t]].loop == loop ? loop : kNoLoop;
    for (TaskId t : targets) loop = v.nodes[node_of[t]].loop == loop ? loop : kNoLoop;
    ViewNode n;
    n.id = "d" + std::to_string(v.nodes.size());
    n.kind = NodeKind::kDatum;
    n.loop = loop;
    const char* verb = static_cast<EdgeKind>(kind) == EdgeKind::RAW ? " read by " : " before ";
    n.lines = {g.data[datum].name, std::to_string(src.size()) + (carried ? " (previous it.)" : "") +
                                       verb + std::to_string(targets.size())};
    v.nodes.push_back(std::move(n));
    for (TaskId t : targets)
      hub_of[{datum, kind, carried, t}] = static_cast<std::uint32_t>(v.nodes.size() - 1);
  }

  struct Agg {
    std::uint32_t edge = 0;
    std::vector<DatumId> data;
    bool data_flow = false;
  };
  std::map<std::tuple<std::uint32_t, std::uint32_t, bool>, Agg> aggs;
  // Adds one dependency to the aggregate edge from -> to; `count` false only adds what it
  // says about crossing and the critical path (a source feeding its hub again).
  auto add = [&](std::uint32_t from, std::uint32_t to, const Item& e, std::uint64_t times,
                 bool cross, bool count) {
    if (from == to) return;
    auto [it, fresh] = aggs.try_emplace({from, to, e.carried});
    if (fresh) {
      it->second.edge = static_cast<std::uint32_t>(v.edges.size());
      ViewEdge ve;
      ve.from = from;
      ve.to = to;
      ve.deps = 0;
      v.edges.push_back(ve);
    }
    Agg& agg = it->second;
    ViewEdge& ve = v.edges[agg.edge];
    ve.critical_hits += e.critical;
    if (!count) return;
    ++ve.deps;
    if (e.kind == EdgeKind::RAW) {
      ve.bytes += g.data[e.datum].bytes * times;
      agg.data_flow = true;
    }
    if (cross) ++ve.cross_deps;
    if (agg.data.size() < 2 &&
        std::find(agg.data.begin(), agg.data.end(), e.datum) == agg.data.end())
      agg.data.push_back(e.datum);
  };
  // (source task, hub) -> whether one of its dependencies through the hub crosses processors.
  std::map<std::pair<TaskId, std::uint32_t>, bool> feeds;
  for (const Item& e : items) {
    const auto hub = hub_of.find({e.datum, static_cast<int>(e.kind), e.carried, e.to});
    if (hub == hub_of.end()) continue;
    bool& crossed = feeds[{e.from, hub->second}];
    crossed = crossed || (a && a->proc[e.from] != a->proc[e.to]);
  }
  std::set<std::pair<TaskId, std::uint32_t>> fed;
  for (const Item& e : items) {
    const LoopId lf = g.tasks[e.from].loop, lt = g.tasks[e.to].loop;
    std::uint64_t times = 1;
    if (e.carried) {
      const std::uint64_t it = iterations_of(g, lt);
      times = it == 0 ? 0 : it - 1;
    } else if (lf != kNoLoop && lf == lt) {
      times = iterations_of(g, lf);
    }
    const bool cross = a && a->proc[e.from] != a->proc[e.to];
    const auto hub = hub_of.find({e.datum, static_cast<int>(e.kind), e.carried, e.to});
    if (hub == hub_of.end()) {
      if (node_of[e.from] == node_of[e.to]) ++v.hidden_deps;  // a self-loop: not drawn
      add(node_of[e.from], node_of[e.to], e, times, cross, true);
      continue;
    }
    const auto feed = feeds.find({e.from, hub->second});
    const bool first = fed.insert(feed->first).second;
    add(node_of[e.from], hub->second, e, times, first && feed->second, first);
    add(hub->second, node_of[e.to], e, times, cross, true);
  }
  for (const auto& [key, agg] : aggs) {
    ViewEdge& ve = v.edges[agg.edge];
    ve.style = std::get<2>(key) ? EdgeStyle::kCarried
               : agg.data_flow  ? EdgeStyle::kData
                                : EdgeStyle::kOrder;
    std::string first =
        agg.data.size() == 1 ? g.data[agg.data.front()].name : std::to_string(ve.deps) + " deps";
    if (agg.data.size() == 1 && ve.deps > 1) first += " (" + std::to_string(ve.deps) + " deps)";
    ve.lines = {first,
                agg.data_flow ? format_bytes(ve.bytes) + "/step" : std::string("order only")};
    if (ve.cross_deps > 0) ve.lines.push_back(std::to_string(ve.cross_deps) + " cross");
  }
}

}  // namespace tgraph::viz::detail
