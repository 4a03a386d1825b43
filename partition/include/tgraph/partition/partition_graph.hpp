// SPDX-License-Identifier: MIT
// The weights METIS and Scotch see: libgraph's undirected task graph (the one that
// `tgraph export` writes as metis or scotch), in 32-bit form, optionally per phase.
#pragma once

#include <cstdint>
#include <vector>

#include "tgraph/graph/step_graph.hpp"
#include "tgraph/graph/undirected.hpp"

namespace tgraph::partition {

struct Options;
enum class ScotchFlavour : std::uint8_t;

/// Totals above which make_undirected scales weights down; the same bound as
/// `tgraph export`, so that the METIS objective matches gpmetis on the exported file.
inline constexpr std::int64_t kMaxLibraryWeight = std::int64_t{1} << 30;

/// The undirected graph the partitioners see (make_undirected with kMaxLibraryWeight).
UndirectedGraph library_graph(const StepGraph& g);

/// 32-bit weights for the libraries.
struct LibraryWeights {
  std::uint32_t ncon = 1;               ///< vertex weights per vertex
  std::vector<std::int32_t> vwgt;       ///< n * ncon, interleaved per vertex
  std::vector<std::int32_t> adjwgt;     ///< one per arc
};

/// Single-constraint (`phase` empty) or multi-constraint weights: with `phase[v]` in
/// [0, nphases), vertex v carries its weight in constraint phase[v] and 0 elsewhere.
LibraryWeights library_weights(const UndirectedGraph& u,
                               const std::vector<std::uint32_t>& phase = {},
                               std::uint32_t nphases = 1);

/// Level of every task: longest path, in edges, from a source of the step's DAG (intra-step
/// edges only, loops not unrolled).
std::vector<std::uint32_t> task_levels(const StepGraph& g);
/// Buckets consecutive levels into at most `nphases` phases of about equal work; then each
/// dynamic loop holding at least `loop_share` of the step's work (cost x iterations; 0: none,
/// the default) becomes a phase of its own: a loop's processors meet at every iteration, so
/// each processor must hold its share of that loop, not only of the whole step; with heavy
/// loops, `rest_phases` (0: nphases) phases for the other tasks. Returns the phase of every
/// task and sets `used` to the number of non-empty phases.
std::vector<std::uint32_t> task_phases(const StepGraph& g, std::uint32_t nphases,
                                       std::uint32_t& used, double loop_share = 0.0,
                                       std::uint32_t rest_phases = 0);
/// The same from the step's task_levels(g), computed once by a caller that needs several
/// phase sets of one step.
std::vector<std::uint32_t> task_phases(const StepGraph& g, const std::vector<std::uint32_t>& level,
                                       std::uint32_t nphases, std::uint32_t& used,
                                       double loop_share = 0.0, std::uint32_t rest_phases = 0);

/// Scotch graph partitioning of `pg` (weights `w`, vertex constraints summed) into `k` parts
/// with `options`' flavour, imbalance and seed: what the `scotch` strategy calls, serialised.
/// K = 1 puts every vertex on part 0 and K >= n vertex i on part i, without calling Scotch.
/// Returns the part of every vertex.
std::vector<std::uint32_t> scotch_partition(const UndirectedGraph& pg, const LibraryWeights& w,
                                            std::uint32_t k, const Options& options);

/// The SCOTCH_STRAT* flags of a flavour (SCOTCH_Num), for Scotch's and PT-Scotch's
/// strategy builders alike.
std::int32_t scotch_strategy_flags(ScotchFlavour f);

/// Edge cut of `part` in the graph's (scaled) weight units: what METIS's objval counts.
std::int64_t edgecut(const UndirectedGraph& u, const std::vector<std::uint32_t>& part);

}  // namespace tgraph::partition
