// SPDX-License-Identifier: MIT
// The graph files of the partitioners' command-line tools: the graph METIS and Scotch see
// (library_graph), as gpmetis and scotch_gpart read it.
#pragma once

#include <cstddef>
#include <cstdint>
#include <string>
#include <string_view>

#include "tgraph/graph/step_graph.hpp"
#include "tgraph/graph/trace.hpp"
#include "tgraph/graph/undirected.hpp"

namespace tgraph::partition {

/// gpmetis input: header "n m 011" (m undirected edges, vertex and edge weights), then one
/// line per vertex: its weight, then "neighbour weight" pairs with 1-based neighbours.
std::string metis_graph_file(const UndirectedGraph& u);
/// scotch_gpart source graph: "0", "n arcs", "0 011" (base 0, edge and vertex loads), then
/// one line per vertex: load, degree, then "edge-load neighbour" pairs (0-based).
std::string scotch_graph_file(const UndirectedGraph& u);

/// metis_graph_file of library_graph(g): `gpmetis F K` then reports the cut METIS's
/// objective (Stats::edgecut of `metis`) has, in the same units.
///
///   write_file_atomic("g.metis", metis_graph_file(trace.steps[0]));
std::string metis_graph_file(const StepGraph& g);
/// scotch_graph_file of library_graph(g).
std::string scotch_graph_file(const StepGraph& g);

/// The interchange formats of one step (the formats of `tgraph export`).
enum class GraphFileFormat : std::uint8_t {
  kJson = 0,    ///< step_graph_json (libgraph): the whole step graph
  kMetis = 1,   ///< metis_graph_file
  kScotch = 2,  ///< scotch_graph_file
};
/// "json", "metis" or "scotch".
std::string_view to_string(GraphFileFormat f);
/// Inverse of to_string; an OptionError of the field "format" listing the formats otherwise.
GraphFileFormat parse_graph_file_format(std::string_view name);

/// Step `step` of `trace` in `format` (`tgraph export`); UsageError naming `trace_name` when
/// the trace has no such step.
///
///   write_file_atomic("g.metis", graph_file(trace, 1, "b.tgt", GraphFileFormat::kMetis));
std::string graph_file(const Trace& trace, std::size_t step, const std::string& trace_name,
                       GraphFileFormat format);

}  // namespace tgraph::partition
