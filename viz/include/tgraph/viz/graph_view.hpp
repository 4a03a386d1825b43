// SPDX-License-Identifier: MIT
// What a step graph picture shows, before Graphviz: nodes (tasks, synchronisation, or
// aggregates), edges with their data, loop clusters, the critical path. Tests check this
// model; graphviz.hpp turns it into DOT, SVG, PNG or PDF.
#pragma once

#include <cstdint>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "tgraph/graph/assignment.hpp"
#include "tgraph/graph/step_graph.hpp"
#include "tgraph/graph/trace.hpp"

namespace tgraph::viz {

struct CriticalPath;  // critical_path.hpp

/// How tasks are aggregated into nodes. Object, kind and processor groups are made per loop
/// body and, outside loops, per region between loops (before loop 0, after loop 0, ...).
enum class Collapse : std::uint8_t {
  kNone = 0,       ///< one node per task (+ signal, wait and reducer nodes with an assignment)
  kObject = 1,     ///< one node per object and loop level (shared tasks: per kind)
  kKind = 2,       ///< one node per task kind and loop level
  kProcessor = 3,  ///< one node per processor and loop level (needs an assignment)
  kLoop = 4        ///< one node per loop body; tasks outside loops stay single
};
/// "none", "object", "kind", "processor" or "loop".
std::string_view to_string(Collapse c);
/// Inverse of to_string; an OptionError of the field `collapse` for another name.
Collapse parse_collapse(std::string_view s);

/// What a node stands for.
enum class NodeKind : std::uint8_t {
  kTask = 0,     ///< one task
  kSignal = 1,   ///< a writer's signal to other processors
  kWait = 2,     ///< a processor waiting for a datum written elsewhere
  kReducer = 3,  ///< sums the per-processor temporaries of a CW group that spans processors
  kGroup = 4,    ///< an aggregate (ViewOptions::collapse)
  kDatum = 5     ///< a datum joining many sources to many targets (collapsed views)
};
/// "task", "signal", "wait", "reducer", "group" or "datum".
std::string_view to_string(NodeKind k);

/// Work of one processor inside a node (aggregates may span processors).
struct ProcessorShare {
  ProcId proc = 0;
  std::uint64_t work_ns = 0;
  friend bool operator==(const ProcessorShare&, const ProcessorShare&) = default;
};

/// One node of the picture.
struct ViewNode {
  std::string id;  ///< DOT node name: t<task>, s<n>, w<n>, r<n>, g<n>, d<n>
  NodeKind kind = NodeKind::kTask;
  std::vector<std::string> lines;     ///< label, one entry per line
  std::vector<ProcessorShare> procs;  ///< empty: no assignment; sorted by processor
  std::uint64_t tasks = 0;            ///< tasks represented (0 for sync nodes)
  std::uint64_t work_ns = 0;          ///< sum of cost x runs of those tasks
  LoopId loop = kNoLoop;              ///< cluster (the loop body it runs in)
  std::uint32_t critical_hits = 0;    ///< task instances of the critical path inside
};

/// How an edge orders its ends.
enum class EdgeStyle : std::uint8_t {
  kData = 0,     ///< read after write (data flows)
  kOrder = 1,    ///< write after read / write after write only (ordering, no data)
  kCarried = 2,  ///< loop-carried: iteration i to i+1
  kInternal = 3  ///< into or out of a signal, wait or reducer
};

/// One edge of the picture.
struct ViewEdge {
  std::uint32_t from = 0;  ///< node index
  std::uint32_t to = 0;
  std::vector<std::string> lines;  ///< label
  EdgeStyle style = EdgeStyle::kData;
  std::uint64_t deps = 1;        ///< dependencies of the step graph represented
  std::uint64_t bytes = 0;       ///< single edge: datum bytes; aggregate: bytes per step
  std::uint64_t cross_deps = 0;  ///< of `deps`, how many join different processors
  std::uint32_t critical_hits = 0;
  double width = 0;  ///< stroke width in points (0: by style, crossing and critical path)
};

/// A loop body drawn as a cluster.
struct ViewCluster {
  LoopId loop = 0;
  std::string label;
};

/// Options of make_graph_view.
struct ViewOptions {
  Collapse collapse = Collapse::kNone;
  const Assignment* assignment = nullptr;  ///< colours, cross edges, sync nodes
  bool critical_path = false;
  /// With critical_path: the path to draw (an executed one, from a timeline: the report's
  /// executed_path) instead of the graph's own longest path; its instances name tasks of
  /// the step drawn.
  const CriticalPath* path = nullptr;
  /// Refuse (OptionError) when the picture would have more nodes than this (0: no limit).
  std::size_t max_nodes = 2000;
  /// Likewise for edges (0: no limit): dot's layout time grows with the edges (bars64's
  /// 11,206 task-level edges take minutes), so large pictures are refused before layout.
  std::size_t max_edges = 4000;
  /// draw_step: a step with more nodes than max_nodes under kNone is drawn collapsed by kind
  /// instead of refused, and its note says so (`tgraph viz` given none of its collapse and
  /// limit options: a captured ODE step's falling phase has thousands of parts).
  bool kinds_when_too_many = false;
  std::string title;  ///< first line of the graph label
  /// false: edge labels become tooltips (shown on hover in SVG) and dot's layout stays
  /// compact, for large collapsed graphs where labels would overlap.
  bool edge_labels = true;
};

/// The picture of one step.
///
///   ViewOptions o;
///   o.collapse = Collapse::kObject;
///   o.assignment = &a.steps[1];
///   const GraphView v = make_graph_view(trace.steps[1], o);
///   write_file_atomic("b.svg", render_graph(v, GraphFormat::kSvg));
struct GraphView {
  std::vector<std::string> title;  ///< graph label lines
  std::uint32_t processors = 0;    ///< 0: no assignment
  Collapse collapse = Collapse::kNone;
  bool critical_path = false;
  std::vector<ViewNode> nodes;
  std::vector<ViewEdge> edges;
  std::vector<ViewCluster> clusters;
  /// Collapsed views: dependencies whose two tasks fall in one node (self-loops, not drawn).
  std::uint64_t hidden_deps = 0;
  std::uint64_t deps = 0;   ///< dependencies of the step (intra-step + loop-carried)
  bool edge_labels = true;  ///< ViewOptions::edge_labels
  bool legend = true;       ///< a legend cluster (processors, shapes, strokes)
  double nodesep = 0.25;    ///< inches between neighbours of one rank (dot's nodesep)
};

/// Builds the picture of `g` (edges derived). Throws OptionError when the assignment does
/// not fit the step, when collapse kProcessor has no assignment, and when the result has
/// more than `max_nodes` nodes or `max_edges` edges (the message suggests `collapse`).
GraphView make_graph_view(const StepGraph& g, const ViewOptions& options);
/// `tgraph viz`: the picture of step `step` of `trace` (read from `trace_name`), titled
/// "<file name>, step S" plus ", <method> on K processors" when `assignment` (whose step S
/// colours it) is given. UsageError when the trace has no such step; make_graph_view's
/// OptionError problems are prefixed with "<trace_name> step S: ".
GraphView trace_step_view(const Trace& trace, const std::string& trace_name, std::size_t step,
                          const TraceAssignment* assignment, ViewOptions options);

/// The picture of an assignment's quotient graph: a node per processor with its work, task
/// count and share of the step's work; an edge per ordered pair of processors with its
/// dependencies, cut bytes and signals, wider the more bytes it carries. `title` is the
/// first line of the label.
GraphView quotient_view(const QuotientGraph& q, const std::string& title);

/// "56 of 252 dependencies join tasks of one node (self-loops, not drawn)": what a
/// collapsed view leaves out (its title says it; `tgraph viz` prints it too).
std::string hidden_deps_note(const GraphView& v);

/// "96 B", "1.5 KiB", "2.25 MiB".
std::string format_bytes(std::uint64_t bytes);
/// "850 ns", "12.3 µs", "4.56 ms", "1.23 s" (three significant digits).
std::string format_ns(double ns);

}  // namespace tgraph::viz
