// SPDX-License-Identifier: MIT
// `tgraph-mpi partition` with the ptscotch method: a step's undirected task graph partitioned across
// MPI ranks, nodes first with PT-Scotch (SCOTCH_dgraphPart on a graph built from per-rank
// slices), then each node's tasks over its cores with sequential Scotch. PT-Scotch 7.0.3
// cannot map onto a two-level nodes x cores target ("kdgraphMapRbMap: not implemented yet").
// Built when CMake finds PT-Scotch (TGRAPH_HAVE_PTSCOTCH defined).
#pragma once

#include <mpi.h>

#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "tgraph/graph/assignment.hpp"
#include "tgraph/graph/step_graph.hpp"
#include "tgraph/graph/trace.hpp"
#include "tgraph/partition/strategy.hpp"

namespace tgraph::mpi {

/// What ptscotch_partition produced and what it cost.
struct PtScotchResult {
  /// proc[task] = node * cores + core, in [0, nodes * cores); the same on every rank.
  Assignment assignment;
  std::uint32_t nodes = 1;
  std::uint32_t cores = 1;
  std::uint64_t vertices = 0;  ///< tasks of the step
  std::uint64_t edges = 0;     ///< undirected edges of the partitioned graph
  /// Weight of the edges whose ends are on different processors (library units: the
  /// weights the `scotch` strategy gives Scotch, so comparable with its edgecut).
  std::int64_t cut = 0;
  std::int64_t node_cut = 0;    ///< weight of the edges between different nodes
  double imbalance = 1.0;       ///< max / mean processor load (library vertex weights)
  double node_imbalance = 1.0;  ///< max / mean node load
  double build_ms = 0.0;        ///< building the slices and the distributed graph (max over ranks)
  double nodes_ms = 0.0;        ///< SCOTCH_dgraphPart into nodes (max over ranks)
  double cores_ms = 0.0;        ///< gathering each node's subgraph and Scotch within it (max)
  double total_ms = 0.0;        ///< all of it, including the cut and load reductions (max)
};

/// Partitions step `g` (edges derived, the same on every rank of `comm`) over `nodes` x
/// `cores` processors; a collective call. Rank r builds only its slice (tasks [n r / R,
/// n (r + 1) / R)) of the undirected graph, weighted as partition::library_graph weights it;
/// node i's subgraph is partitioned by rank i mod R. Uses `options`' seed, Scotch flavour and
/// imbalance (its square root at each of the two levels, so that the product stays within).
/// Throws UsageError for 0 nodes or cores, std::runtime_error when PT-Scotch fails.
PtScotchResult ptscotch_partition(const StepGraph& g, std::uint32_t nodes, std::uint32_t cores,
                                  const partition::Options& options, MPI_Comm comm);

/// Steps [first, last) of a trace partitioned one after the other by ptscotch_partition.
struct PtScotchTraceResult {
  TraceAssignment assignment;         ///< method "ptscotch", k = nodes x cores, one per step
  std::vector<std::uint64_t> hashes;  ///< each partitioned step's structural hash (for the .tga)
  /// Each step's figures (step first + i; their assignments are in `assignment`).
  std::vector<PtScotchResult> steps;
  std::int64_t cut = 0, node_cut = 0;  ///< summed over the steps
  double imbalance = 1.0;              ///< the worst step's
  double partition_ms = 0.0;           ///< summed over the steps
};

/// ptscotch_partition of every step of `trace` in [first, last) (within the trace); a
/// collective call, the same result on every rank.
PtScotchTraceResult ptscotch_partition_trace(const Trace& trace, std::size_t first,
                                             std::size_t last, std::uint32_t nodes,
                                             std::uint32_t cores,
                                             const partition::Options& options, MPI_Comm comm);

/// What `tgraph-mpi partition` reports beside a PtScotchTraceResult.
struct PtScotchRun {
  std::string trace, output;  ///< the files, as named on the command line
  int ranks = 1;
  std::uint32_t nodes = 1, cores = 1;
  std::size_t first = 0;   ///< the first partitioned step
  double read_ms = 0;      ///< reading the trace (slowest rank)
  double max_rss_mib = 0;  ///< largest peak resident set of any rank
};

/// The JSON report of `tgraph-mpi partition`: method, trace, output, ranks, nodes, cores,
/// k, steps, cut, node_cut, imbalance, read_ms, partition_ms, max_rss_mib and per_step (each
/// step's tasks, edges, cut, node_cut, imbalance, node_imbalance and times).
std::string ptscotch_json(const PtScotchTraceResult& r, const PtScotchRun& run);
/// The same as text (a line, and the output file when one was written).
std::string ptscotch_text(const PtScotchTraceResult& r, const PtScotchRun& run);

/// What `tgraph-mpi partition` is asked for: the trace file, the .tga to write (none when
/// empty), the parts, one step or every step, the options and the Scotch flavour's name.
struct PtScotchFileOptions {
  std::string trace, output;
  std::uint32_t nodes = 0, cores = 1;
  std::optional<std::size_t> step;
  partition::Options options;
  std::string scotch = "quality";
};

/// The partition of a trace file and what its report says beside it.
struct PtScotchFileReport {
  PtScotchTraceResult result;
  PtScotchRun run;
};

/// `tgraph-mpi partition`, a collective call: every rank reads the trace (an OptionError of
/// `nodes`, `cores` or `step` on every rank for 0 nodes or cores or a step past the
/// trace's), ptscotch_partition_trace of the step or steps, and rank 0 writes `output`
/// unless it is empty.
PtScotchFileReport ptscotch_partition_file(const PtScotchFileOptions& o, MPI_Comm comm);

}  // namespace tgraph::mpi
