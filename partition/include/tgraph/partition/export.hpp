// SPDX-License-Identifier: MIT
// The graph files of the partitioners' command-line tools: the graph METIS and Scotch see
// (library_graph), as gpmetis and scotch_gpart read it.
#pragma once

#include <string>

#include "tgraph/graph/step_graph.hpp"
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

}  // namespace tgraph::partition
