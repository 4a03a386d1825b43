// SPDX-License-Identifier: MIT
// The task-level picture of a step: one node per task, and for an assignment the signal,
// wait and reducer nodes that make its synchronisation explicit.
#include <algorithm>
#include <map>
#include <tuple>
#include <unordered_map>

#include "graph_view_builders.hpp"

namespace tgraph::viz::detail {
namespace {

constexpr std::uint32_t kNoNode = 0xffffffffu;

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

}  // namespace

void build_task_view(const StepGraph& g, const ViewOptions& o, const CriticalPath* cp,
                     GraphView& v) {
  TaskViewBuilder(g, o, cp, v).build();
}

}  // namespace tgraph::viz::detail
