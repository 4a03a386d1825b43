// SPDX-License-Identifier: MIT
// The step graph made undirected, as graph partitioners (METIS, Scotch) take it.
#pragma once

#include <cstdint>
#include <vector>

#include "tgraph/graph/step_graph.hpp"

namespace tgraph {

/// Symmetric CSR graph: one vertex per task, no self loops, parallel edges merged.
struct UndirectedGraph {
  std::vector<std::uint32_t> xadj;     ///< size n + 1
  std::vector<std::uint32_t> adjncy;   ///< neighbours, sorted per vertex
  std::vector<std::int64_t> adjwgt;    ///< edge weight, equal in both directions, >= 1
  std::vector<std::int64_t> vwgt;      ///< vertex weight, >= 1
  std::uint32_t vertices() const { return static_cast<std::uint32_t>(vwgt.size()); }
  /// Undirected edges (each counted once).
  std::uint64_t edges() const { return adjncy.size() / 2; }
};

/// Vertex weight = cost x runs of the task (at least 1); edge weight = sum of the bytes of
/// the data carried by the edges between two tasks (intra-step and loop-carried, at least 1
/// each). When `max_total_vertex_weight` > 0 and the total exceeds it, vertex weights are
/// scaled down proportionally (rounded, at least 1) so 32-bit partitioners cannot overflow;
/// likewise `max_total_edge_weight` for edge weights.
UndirectedGraph make_undirected(const StepGraph& g, std::int64_t max_total_vertex_weight = 0,
                                std::int64_t max_total_edge_weight = 0);

}  // namespace tgraph
