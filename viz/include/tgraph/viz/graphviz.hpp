// SPDX-License-Identifier: MIT
// GraphView -> Graphviz: the graph is built with libcgraph (agopen, agnode, agedge,
// agsafeset), written as DOT by agwrite, or laid out by libgvc's dot engine and rendered.
#pragma once

#include <cstddef>
#include <string>
#include <string_view>

#include "tgraph/viz/graph_view.hpp"

namespace tgraph::viz {

/// Output formats of a step graph.
enum class GraphFormat : std::uint8_t { kDot = 0, kSvg = 1, kPng = 2, kPdf = 3 };
/// "dot", "svg", "png" or "pdf".
std::string_view to_string(GraphFormat f);
/// Format from a file name's extension; throws UsageError naming the file (the field
/// `output`) otherwise.
GraphFormat graph_format_of(const std::string& path);

/// Above this many edges render_graph lays out with dot's quick settings (crossing
/// minimisation cut short: mclimit 0.1, remincross off; network simplex limited: nslimit 1;
/// straight edges): a 1,979-edge view took 82 s with dot's defaults, 2.6 s with these.
inline constexpr std::size_t kQuickLayoutEdges = 500;
/// The most edges draw_step lays out (svg, png, pdf): 4,104 edges took 37 s even with the
/// quick settings (2 shared cores). A larger picture is refused with the aggregate that
/// fits; a .dot file (no layout) has only ViewOptions::max_edges.
inline constexpr std::size_t kLayoutEdges = 2500;

/// The picture as DOT text, without layout (what golden tests compare).
std::string to_dot(const GraphView& view);
/// The picture laid out by dot and rendered (kDot: same as to_dot). Graphviz is not
/// thread-safe: calls are serialised by a lock. Throws std::runtime_error when Graphviz
/// fails (for instance a missing cairo plugin for png and pdf).
std::string render_graph(const GraphView& view, GraphFormat format);

/// Step `step` of `trace` (named `trace_name`; trace_step_view) drawn into `output` in the
/// format of its extension (graph_format_of), atomically. Returns hidden_deps_note when a
/// collapsed view leaves dependencies out, else "", and under kinds_when_too_many a note
/// naming the fields `{collapse}`, `{max_nodes}`, `{max_edges}` when it drew kinds.
std::string draw_step(const Trace& trace, const std::string& trace_name, std::size_t step,
                      const TraceAssignment* assignment, const ViewOptions& options,
                      const std::string& output);

}  // namespace tgraph::viz
