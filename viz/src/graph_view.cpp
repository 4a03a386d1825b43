// SPDX-License-Identifier: MIT
// The picture model of a step: task nodes with synchronisation (signal, wait, reducer) made
// explicit for an assignment, or aggregates (ViewOptions::collapse).
#include "tgraph/viz/graph_view.hpp"

#include <algorithm>
#include <cstdio>
#include <filesystem>
#include <map>

#include "tgraph/graph/enum_names.hpp"
#include "tgraph/graph/error.hpp"
#include "tgraph/graph/metrics.hpp"
#include "tgraph/viz/critical_path.hpp"
#include "graph_view_builders.hpp"

namespace tgraph::viz {

std::string detail::sig3(double v) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.3g", v);
  return buf;
}

namespace {

using detail::sig3;

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
  return parse_enum(
      s, {Collapse::kNone, Collapse::kObject, Collapse::kKind, Collapse::kProcessor, Collapse::kLoop},
      "collapse");
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
      throw OptionError("assignment", "has " + std::to_string(a->proc.size()) +
                                          " tasks, the step has " + std::to_string(g.tasks.size()));
    if (a->k == 0) throw OptionError("assignment", "has k = 0");
    for (ProcId p : a->proc)
      if (p >= a->k)
        throw OptionError("assignment", "processor " + std::to_string(p) +
                                            " out of range (k = " + std::to_string(a->k) + ")");
  }
  if (o.collapse == Collapse::kProcessor && !a)
    throw OptionError("collapse", "processor needs an assignment (.tga)");
  // The limit's field (max_nodes, max_edges) names the problem; aggregating is the way out.
  auto too_many = [&](std::size_t count, const std::string& what, std::size_t limit) {
    return OptionError("max_" + what, "the picture would have " + std::to_string(count) + " " +
                                          what + ", more than " + std::to_string(limit) +
                                          ": aggregate with {collapse} object, kind, processor "
                                          "or loop (or raise the limit)");
  };
  if (o.collapse == Collapse::kNone && o.max_nodes != 0 && g.tasks.size() > o.max_nodes)
    throw too_many(g.tasks.size(), "nodes", o.max_nodes);

  GraphView v;
  v.processors = a ? a->k : 0;
  v.collapse = o.collapse;
  v.critical_path = o.critical_path;
  CriticalPath cp;
  if (o.critical_path) cp = o.path ? *o.path : critical_path(g);
  const CriticalPath* cpp = o.critical_path ? &cp : nullptr;
  if (o.collapse == Collapse::kNone) {
    detail::build_task_view(g, o, cpp, v);
  } else {
    detail::build_collapsed_view(g, o, cpp, v);
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
    v.title.push_back(std::string(o.path ? "executed critical path" : "critical path") +
                      " (thick, double border): " +
                      format_ns(static_cast<double>(cp.length_ns)) + " over " +
                      std::to_string(cp.instances.size()) + " task instances" +
                      loop_summary(g, cp));
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
  } catch (const OptionError& e) {
    throw OptionError(e.option(), trace_name + " step " + std::to_string(step) + ": " + e.problem());
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