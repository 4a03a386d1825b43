// SPDX-License-Identifier: MIT
// The picture model of a step: task nodes with synchronisation (signal, wait, reducer) made
// explicit for an assignment, or aggregates for --collapse.
#include "tgraph/viz/graph_view.hpp"

#include <algorithm>
#include <cstdio>
#include <filesystem>
#include <map>
#include <set>
#include <tuple>
#include <unordered_map>

#include "tgraph/graph/error.hpp"
#include "tgraph/graph/metrics.hpp"
#include "tgraph/viz/critical_path.hpp"

namespace tgraph::viz {
namespace {

constexpr std::uint32_t kNoNode = 0xffffffffu;

std::string sig3(double v) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.3g", v);
  return buf;
}

std::uint64_t iterations_of(const StepGraph& g, LoopId l) {
  return l == kNoLoop ? 1 : g.loops[l].iterations;
}

// One dependency between two nodes of the task-level picture.
struct Dep {
  std::uint32_t from = 0, to = 0;
  DatumId datum = 0;
  EdgeKind kind = EdgeKind::RAW;
  bool carried = false;
  std::uint32_t critical = 0;
};

// Builds the task-level picture (Collapse::kNone).
class TaskViewBuilder {
 public:
  TaskViewBuilder(const StepGraph& g, const ViewOptions& o, const CriticalPath* cp, GraphView& v)
      : g_(g), a_(o.assignment), cp_(cp), v_(v) {}

  void build() {
    for (TaskId t = 0; t < g_.tasks.size(); ++t) add_task_node(t);
    std::vector<Dep> deps;
    for (std::uint32_t i = 0; i < g_.edges.size(); ++i) {
      const Edge& e = g_.edges[i];
      deps.push_back({e.from, e.to, e.datum, e.kind, false, cp_ ? cp_->edge_hits[i] : 0});
    }
    for (std::uint32_t i = 0; i < g_.carried_edges.size(); ++i) {
      const Edge& e = g_.carried_edges[i];
      deps.push_back({e.from, e.to, e.datum, e.kind, true, cp_ ? cp_->carried_hits[i] : 0});
    }
    if (a_) deps = add_reducers(std::move(deps));
    for (const Dep& d : deps) {
      if (a_ && proc_of(d.from) != proc_of(d.to)) {
        add_crossing(d);
      } else {
        add_edge(d.from, d.to, d.carried ? EdgeStyle::kCarried : style_of(d.kind), d.datum,
                 d.kind == EdgeKind::RAW, d.critical, 0);
      }
    }
    if (a_) add_loop_control();
  }

 private:
  static EdgeStyle style_of(EdgeKind k) {
    return k == EdgeKind::RAW ? EdgeStyle::kData : EdgeStyle::kOrder;
  }

  ProcId proc_of(std::uint32_t node) const { return v_.nodes[node].procs.front().proc; }

  std::string object_name(TaskId t) const {
    const ObjectId o = g_.tasks[t].object;
    return o == kNoObject ? std::string("(shared)") : g_.objects[o].name;
  }

  void add_task_node(TaskId t) {
    const Task& task = g_.tasks[t];
    ViewNode n;
    n.id = "t" + std::to_string(t);
    n.kind = NodeKind::kTask;
    n.tasks = 1;
    n.work_ns = task.cost_ns * g_.runs(t);
    n.loop = task.loop;
    n.critical_hits = cp_ ? cp_->task_hits[t] : 0;
    std::string cost = format_ns(static_cast<double>(task.cost_ns));
    if (task.loop != kNoLoop) cost += " \xC3\x97" + std::to_string(g_.runs(t));  // ×
    if (a_) {
      n.procs.push_back({a_->proc[t], n.work_ns});
      cost = "p" + std::to_string(a_->proc[t]) + " \xC2\xB7 " + cost;  // ·
    }
    n.lines = {g_.kind_name(t), object_name(t), cost};
    v_.nodes.push_back(std::move(n));
  }

  std::uint32_t add_sync_node(NodeKind kind, const std::string& prefix, ProcId p, LoopId loop,
                              std::vector<std::string> lines) {
    ViewNode n;
    n.id = prefix + std::to_string(sync_count_[prefix]++);
    n.kind = kind;
    n.procs.push_back({p, 0});
    n.loop = loop;
    n.lines = std::move(lines);
    v_.nodes.push_back(std::move(n));
    return static_cast<std::uint32_t>(v_.nodes.size() - 1);
  }

  // Edges between the same two nodes with the same style are merged; the label lists data.
  void add_edge(std::uint32_t from, std::uint32_t to, EdgeStyle style, DatumId datum, bool data,
                std::uint32_t critical, std::uint64_t cross) {
    const auto key = std::make_tuple(from, to, static_cast<int>(style));
    auto [it, fresh] = edge_index_.try_emplace(key, static_cast<std::uint32_t>(v_.edges.size()));
    if (fresh) {
      ViewEdge e;
      e.from = from;
      e.to = to;
      e.style = style;
      e.deps = 0;
      v_.edges.push_back(e);
      edge_data_.emplace_back();
    }
    ViewEdge& e = v_.edges[it->second];
    auto& names = edge_data_[it->second];
    const bool new_datum = std::find(names.begin(), names.end(), datum) == names.end();
    ++e.deps;
    e.cross_deps += cross;
    e.critical_hits += critical;
    if (new_datum) {
      names.push_back(datum);
      if (data) e.bytes += g_.data[datum].bytes;
    }
    if (style == EdgeStyle::kInternal) return;  // unlabelled
    // Label: up to three data names, then the bytes (data edges) or "order".
    std::string line;
    for (std::size_t i = 0; i < names.size() && i < 3; ++i)
      line += (i ? ", " : "") + g_.data[names[i]].name;
    if (names.size() > 3) line += ", +" + std::to_string(names.size() - 3);
    e.lines = {line, e.bytes > 0 ? format_bytes(e.bytes) : std::string("order only")};
  }

  // CW groups whose writers span processors get a reducer on the first writer's processor;
  // dependencies leaving the group's writers on that datum leave from the reducer instead.
  std::vector<Dep> add_reducers(std::vector<Dep> deps) {
    struct Group {
      DatumId datum = 0;
      LoopId loop = kNoLoop;
      ProcId home = 0;
      bool spans = false;
      std::vector<TaskId> writers;
    };
    std::vector<Group> groups;
    std::vector<std::uint32_t> open(g_.data.size(), kNoNode);
    std::unordered_map<std::uint64_t, std::uint32_t> group_of;  // (task << 32 | datum) -> group
    for (TaskId t = 0; t < g_.tasks.size(); ++t)
      for (const Access& acc : g_.accesses_of(t)) {
        std::uint32_t& cur = open[acc.datum];
        if (acc.mode != AccessMode::CW) {
          cur = kNoNode;
          continue;
        }
        if (cur != kNoNode && groups[cur].loop != g_.tasks[t].loop) cur = kNoNode;
        if (cur == kNoNode) {
          cur = static_cast<std::uint32_t>(groups.size());
          groups.push_back({acc.datum, g_.tasks[t].loop, a_->proc[t], false, {}});
        }
        Group& gr = groups[cur];
        gr.writers.push_back(t);
        gr.spans = gr.spans || a_->proc[t] != gr.home;
        group_of[(std::uint64_t{t} << 32) | acc.datum] = cur;
      }
    std::vector<std::uint32_t> reducer(groups.size(), kNoNode);
    for (std::uint32_t i = 0; i < groups.size(); ++i) {
      const Group& gr = groups[i];
      if (!gr.spans) continue;
      reducer[i] = add_sync_node(
          NodeKind::kReducer, "r", gr.home, gr.loop,
          {"reduce", g_.data[gr.datum].name, std::to_string(gr.writers.size()) + " writers"});
      v_.nodes[reducer[i]].procs.front().proc = gr.home;
    }
    auto group_at = [&](std::uint32_t task, DatumId d) {
      const auto it = group_of.find((std::uint64_t{task} << 32) | d);
      return it == group_of.end() ? kNoNode : it->second;
    };
    std::vector<Dep> out;
    std::map<std::tuple<std::uint32_t, std::uint32_t, DatumId, int, bool>, std::size_t> merged;
    std::map<std::pair<TaskId, std::uint32_t>, std::uint32_t> writer_critical;
    for (const Dep& d : deps) {
      const std::uint32_t gi = group_at(d.from, d.datum);
      if (gi == kNoNode || reducer[gi] == kNoNode || group_at(d.to, d.datum) == gi) {
        out.push_back(d);
        continue;
      }
      writer_critical[{d.from, gi}] += d.critical;
      const auto key =
          std::make_tuple(reducer[gi], d.to, d.datum, static_cast<int>(d.kind), d.carried);
      auto [it, fresh] = merged.try_emplace(key, out.size());
      if (fresh) {
        Dep r = d;
        r.from = reducer[gi];
        out.push_back(r);
      } else {
        out[it->second].critical += d.critical;
      }
    }
    for (std::uint32_t i = 0; i < groups.size(); ++i) {
      if (reducer[i] == kNoNode) continue;
      for (TaskId w : groups[i].writers) {
        const auto it = writer_critical.find({w, i});
        out.push_back({w, reducer[i], groups[i].datum, EdgeKind::RAW, false,
                       it == writer_critical.end() ? 0 : it->second});
      }
    }
    return out;
  }

  // from -> signal -> wait -> to, the signal on the writer's processor, the wait on the
  // reader's; both inside the loop cluster only when both ends are in the same loop.
  void add_crossing(const Dep& d) {
    const LoopId lf = v_.nodes[d.from].loop, lt = v_.nodes[d.to].loop;
    const LoopId loop = lf == lt ? lf : kNoLoop;
    const std::uint32_t s = signal(d.from, d.datum, loop);
    const std::uint32_t w = wait(s, proc_of(d.to), d.datum, loop);
    add_edge(d.from, s, EdgeStyle::kInternal, d.datum, false, d.critical, 0);
    add_edge(s, w, d.carried ? EdgeStyle::kCarried : style_of(d.kind), d.datum,
             d.kind == EdgeKind::RAW, d.critical, 1);
    add_edge(w, d.to, EdgeStyle::kInternal, d.datum, false, d.critical, 0);
  }

  std::uint32_t signal(std::uint32_t from, DatumId datum, LoopId loop) {
    const auto key = std::make_tuple(from, datum, loop);
    const auto it = signals_.find(key);
    if (it != signals_.end()) return it->second;
    const std::uint32_t s =
        add_sync_node(NodeKind::kSignal, "s", proc_of(from), loop, {"signal", g_.data[datum].name});
    signals_.emplace(key, s);
    return s;
  }

  std::uint32_t wait(std::uint32_t signal, ProcId p, DatumId datum, LoopId loop) {
    const auto key = std::make_pair(signal, p);
    const auto it = waits_.find(key);
    if (it != waits_.end()) return it->second;
    const std::uint32_t w =
        add_sync_node(NodeKind::kWait, "w", p, loop, {"wait", g_.data[datum].name});
    waits_.emplace(key, w);
    return w;
  }

  // A loop replicated on several processors: each waits for the conditional break's
  // decision before its next iteration.
  void add_loop_control() {
    for (LoopId l = 0; l < g_.loops.size(); ++l) {
      const Loop& loop = g_.loops[l];
      if (loop.first >= loop.last) continue;
      const TaskId brk = loop.last - 1;
      std::map<ProcId, TaskId> first_on;
      for (TaskId t = loop.first; t < loop.last; ++t) first_on.try_emplace(a_->proc[t], t);
      for (const auto& [p, t] : first_on) {
        if (p == a_->proc[brk]) continue;
        const std::uint32_t s = signal(brk, loop.condition, l);
        const std::uint32_t w = wait(s, p, loop.condition, l);
        add_edge(brk, s, EdgeStyle::kInternal, loop.condition, false, 0, 0);
        add_edge(s, w, EdgeStyle::kCarried, loop.condition, false, 0, 1);
        v_.edges.back().lines = {g_.data[loop.condition].name, "next iteration"};
        add_edge(w, t, EdgeStyle::kInternal, loop.condition, false, 0, 0);
      }
    }
  }

  const StepGraph& g_;
  const Assignment* a_;
  const CriticalPath* cp_;
  GraphView& v_;
  std::map<std::string, std::uint32_t> sync_count_;
  std::map<std::tuple<std::uint32_t, std::uint32_t, int>, std::uint32_t> edge_index_;
  std::vector<std::vector<DatumId>> edge_data_;
  std::map<std::tuple<std::uint32_t, DatumId, LoopId>, std::uint32_t> signals_;
  std::map<std::pair<std::uint32_t, ProcId>, std::uint32_t> waits_;
};

// Builds an aggregated picture (every other Collapse).
void build_groups(const StepGraph& g, const ViewOptions& o, const CriticalPath* cp, GraphView& v) {
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

std::string loop_summary(const StepGraph& g, const CriticalPath& cp) {
  std::map<LoopId, std::uint32_t> its;  // loop -> iterations the path passes through
  std::map<LoopId, std::uint32_t> last;
  for (const TaskInstance& i : cp.instances) {
    const LoopId l = g.tasks[i.task].loop;
    if (l == kNoLoop) continue;
    auto [it, fresh] = last.try_emplace(l, i.iteration);
    if (fresh || it->second != i.iteration) ++its[l];
    it->second = i.iteration;
  }
  std::string s;
  for (const auto& [l, n] : its)
    s += ", loop " + std::to_string(l) + ": " + std::to_string(n) + " of " +
         std::to_string(g.loops[l].iterations) + " iterations";
  return s;
}

}  // namespace

std::string hidden_deps_note(const GraphView& v) {
  return std::to_string(v.hidden_deps) + " of " + std::to_string(v.deps) +
         (v.deps == 1 ? " dependency joins" : " dependencies join") +
         " tasks of one node (self-loops, not drawn)";
}

std::string_view to_string(Collapse c) {
  switch (c) {
    case Collapse::kNone:
      return "none";
    case Collapse::kObject:
      return "object";
    case Collapse::kKind:
      return "kind";
    case Collapse::kProcessor:
      return "processor";
    case Collapse::kLoop:
      return "loop";
  }
  return "?";
}

Collapse parse_collapse(std::string_view s) {
  for (Collapse c :
       {Collapse::kNone, Collapse::kObject, Collapse::kKind, Collapse::kProcessor, Collapse::kLoop})
    if (to_string(c) == s) return c;
  throw UsageError("--collapse " + std::string(s) +
                   ": expected none, object, kind, processor or loop");
}

std::string_view to_string(NodeKind k) {
  switch (k) {
    case NodeKind::kTask:
      return "task";
    case NodeKind::kSignal:
      return "signal";
    case NodeKind::kWait:
      return "wait";
    case NodeKind::kReducer:
      return "reducer";
    case NodeKind::kGroup:
      return "group";
    case NodeKind::kDatum:
      return "datum";
  }
  return "?";
}

std::string format_bytes(std::uint64_t bytes) {
  if (bytes < 1024) return std::to_string(bytes) + " B";
  const char* units[] = {"KiB", "MiB", "GiB", "TiB"};
  double v = static_cast<double>(bytes);
  int u = -1;
  while (v >= 1024 && u < 3) {
    v /= 1024;
    ++u;
  }
  return sig3(v) + " " + units[u];
}

std::string format_ns(double ns) {
  if (ns < 1e3) return sig3(ns) + " ns";
  if (ns < 1e6) return sig3(ns / 1e3) + " \xC2\xB5s";  // µs
  if (ns < 1e9) return sig3(ns / 1e6) + " ms";
  return sig3(ns / 1e9) + " s";
}

GraphView make_graph_view(const StepGraph& g, const ViewOptions& o) {
  const Assignment* a = o.assignment;
  if (a) {
    if (a->proc.size() != g.tasks.size())
      throw UsageError("--assign: the assignment has " + std::to_string(a->proc.size()) +
                       " tasks, the step has " + std::to_string(g.tasks.size()));
    if (a->k == 0) throw UsageError("--assign: the assignment has k = 0");
    for (ProcId p : a->proc)
      if (p >= a->k)
        throw UsageError("--assign: processor " + std::to_string(p) +
                         " out of range (k = " + std::to_string(a->k) + ")");
  }
  if (o.collapse == Collapse::kProcessor && !a)
    throw UsageError("--collapse processor needs an assignment (--assign A.tga)");
  auto too_many = [&](std::size_t count, const char* what, std::size_t limit) {
    return UsageError(
        "the picture would have " + std::to_string(count) + " " + what + ", more than --max-" +
        what + " " + std::to_string(limit) +
        ": aggregate with --collapse object, kind, processor or loop (or raise --max-" + what +
        ")");
  };
  if (o.collapse == Collapse::kNone && o.max_nodes != 0 && g.tasks.size() > o.max_nodes)
    throw too_many(g.tasks.size(), "nodes", o.max_nodes);

  GraphView v;
  v.processors = a ? a->k : 0;
  v.collapse = o.collapse;
  v.critical_path = o.critical_path;
  CriticalPath cp;
  if (o.critical_path) cp = critical_path(g);
  const CriticalPath* cpp = o.critical_path ? &cp : nullptr;
  if (o.collapse == Collapse::kNone) {
    TaskViewBuilder(g, o, cpp, v).build();
  } else {
    build_groups(g, o, cpp, v);
  }
  if (o.max_nodes != 0 && v.nodes.size() > o.max_nodes)
    throw too_many(v.nodes.size(), "nodes", o.max_nodes);
  if (o.max_edges != 0 && v.edges.size() > o.max_edges)
    throw too_many(v.edges.size(), "edges", o.max_edges);

  for (LoopId l = 0; l < g.loops.size(); ++l) {
    const bool used =
        std::any_of(v.nodes.begin(), v.nodes.end(), [l](const ViewNode& n) { return n.loop == l; });
    if (!used) continue;
    const Loop& loop = g.loops[l];
    std::string label = "loop " + std::to_string(l) + ": " + std::to_string(loop.iterations) +
                        (loop.iterations == 1 ? " iteration" : " iterations");
    if (loop.max_iterations != 0) label += " (max " + std::to_string(loop.max_iterations) + ")";
    v.clusters.push_back({l, label});
  }

  const Metrics m = compute_metrics(g);
  if (!o.title.empty()) v.title.push_back(o.title);
  v.title.push_back(std::to_string(m.tasks) + " tasks \xC2\xB7 " + std::to_string(m.edges) +
                    " dependencies \xC2\xB7 work " + format_ns(static_cast<double>(m.work_ns)) +
                    " \xC2\xB7 span " + format_ns(static_cast<double>(m.span_ns)) +
                    " \xC2\xB7 parallelism " + sig3(m.parallelism));
  if (a) {
    std::uint64_t cross = 0;
    for (const Edge& e : g.edges) cross += a->proc[e.from] != a->proc[e.to] ? 1 : 0;
    for (const Edge& e : g.carried_edges) cross += a->proc[e.from] != a->proc[e.to] ? 1 : 0;
    v.title.push_back(std::to_string(a->k) + " processors \xC2\xB7 " + std::to_string(cross) +
                      " dependencies cross processors (red)");
  }
  v.deps = m.edges;
  v.edge_labels = o.edge_labels;
  if (o.collapse != Collapse::kNone)
    v.title.push_back("collapsed by " + std::string(to_string(o.collapse)) +
                      ": work = cost \xC3\x97 runs, edge bytes per step; " + hidden_deps_note(v));
  if (o.critical_path)
    v.title.push_back(
        "critical path (thick, double border): " + format_ns(static_cast<double>(cp.length_ns)) +
        " over " + std::to_string(cp.instances.size()) + " task instances" + loop_summary(g, cp));
  return v;
}

GraphView trace_step_view(const Trace& trace, const std::string& trace_name, std::size_t step,
                          const TraceAssignment* assignment, ViewOptions options) {
  const StepGraph& g = step_at(trace, step, trace_name);
  options.title =
      std::filesystem::path(trace_name).filename().string() + ", step " + std::to_string(step);
  if (assignment) {
    options.assignment = step < assignment->steps.size() ? &assignment->steps[step] : nullptr;
    options.title +=
        ", " + assignment->method + " on " + std::to_string(assignment->k) + " processors";
  }
  try {
    return make_graph_view(g, options);
  } catch (const UsageError& e) {
    throw UsageError(trace_name + ": step " + std::to_string(step) + ": " + e.what());
  }
}

GraphView quotient_view(const QuotientGraph& q, const std::string& title) {
  GraphView v;
  v.processors = static_cast<std::uint32_t>(q.load_ns.size());
  v.collapse = Collapse::kProcessor;
  v.legend = false;  // every node names its processor
  v.nodesep = 0.8;   // room for the labels of the edges both ways between two processors
  std::uint64_t work = 0, tasks = 0, deps = 0, bytes = 0, signals = 0, max_bytes = 0;
  for (ProcId p = 0; p < v.processors; ++p) {
    work += q.load_ns[p];
    tasks += q.tasks[p];
  }
  for (ProcId p = 0; p < v.processors; ++p) {
    ViewNode n;
    n.id = "p" + std::to_string(p);
    n.kind = NodeKind::kGroup;
    n.procs = {{p, q.load_ns[p]}};
    n.tasks = q.tasks[p];
    n.work_ns = q.load_ns[p];
    const double share =
        work == 0 ? 0.0 : 100.0 * static_cast<double>(q.load_ns[p]) / static_cast<double>(work);
    n.lines = {"p" + std::to_string(p),
               "work " + format_ns(static_cast<double>(q.load_ns[p])) + " (" + sig3(share) + "%)",
               std::to_string(q.tasks[p]) + (q.tasks[p] == 1 ? " task" : " tasks")};
    v.nodes.push_back(std::move(n));
  }
  for (const QuotientEdge& e : q.edges) max_bytes = std::max(max_bytes, e.bytes);
  for (const QuotientEdge& e : q.edges) {
    ViewEdge ve;
    ve.from = e.from;
    ve.to = e.to;
    ve.deps = e.deps + e.carried_deps;
    ve.bytes = e.bytes;
    ve.style = ve.deps == 0 ? EdgeStyle::kOrder : EdgeStyle::kData;  // only loop decisions
    // Short lines: labels of the edges both ways between two processors sit side by side.
    std::string first = std::to_string(ve.deps) + (ve.deps == 1 ? " dep" : " deps");
    if (e.carried_deps > 0) first += " (" + std::to_string(e.carried_deps) + " carried)";
    ve.lines = {first, format_bytes(e.bytes),
                std::to_string(e.signals) + (e.signals == 1 ? " signal" : " signals")};
    ve.width = max_bytes == 0
                   ? 1.0
                   : 1.0 + 5.0 * static_cast<double>(e.bytes) / static_cast<double>(max_bytes);
    v.edges.push_back(std::move(ve));
    deps += e.deps + e.carried_deps;
    bytes += e.bytes;
    signals += e.signals;
  }
  if (!title.empty()) v.title.push_back(title);
  v.title.push_back(std::to_string(v.processors) + " processors \xC2\xB7 " + std::to_string(tasks) +
                    " tasks \xC2\xB7 work " + format_ns(static_cast<double>(work)));
  v.title.push_back("cut: " + std::to_string(deps) + " dependencies \xC2\xB7 " +
                    format_bytes(bytes) + " \xC2\xB7 " + std::to_string(signals) +
                    " signals per execution");
  return v;
}

}  // namespace tgraph::viz
