// SPDX-License-Identifier: MIT
// Factories of the built-in strategies (one per source file) and shared helpers.
#pragma once

#include <cstdint>
#include <memory>
#include <optional>
#include <vector>

#include "tgraph/partition/partition_graph.hpp"
#include "tgraph/partition/strategy.hpp"

namespace tgraph::partition::detail {

std::unique_ptr<Strategy> make_single();
std::unique_ptr<Strategy> make_roundrobin();
std::unique_ptr<Strategy> make_random();
std::unique_ptr<Strategy> make_owner();
std::unique_ptr<Strategy> make_metis();
std::unique_ptr<Strategy> make_metis_relabel();
std::unique_ptr<Strategy> make_scotch();
std::unique_ptr<Strategy> make_sticky();
std::unique_ptr<Strategy> make_list();

/// An execution order for the fixed mapping `a.proc` (Assignment::order): an event-driven
/// list schedule in which each idle processor starts, of its tasks whose inputs have
/// arrived, the one with the longest path to the end of the step; loops kept as blocks
/// (list's rule). Empty for k = 1.
std::vector<std::vector<TaskId>> list_order(const StepGraph& g, const Assignment& a,
                                            const model::CostModel& model);

/// Work of every task (cost x runs).
std::vector<std::uint64_t> task_work(const StepGraph& g);
/// Per-processor load of `proc`.
std::vector<std::uint64_t> loads(const std::vector<std::uint64_t>& work,
                                 const std::vector<ProcId>& proc, std::uint32_t k);
/// max load / mean load (1 for zero work).
double imbalance(const std::vector<std::uint64_t>& load);

/// Tasks grouped as processors meet: group 0 the tasks outside heavy loops, then one group
/// per dynamic loop holding at least `loop_share` of the step's work (0: no loop group).
struct LoopGroups {
  std::vector<std::uint32_t> group;  ///< per task
  std::uint32_t count = 1;
};
LoopGroups loop_groups(const StepGraph& g, const std::vector<std::uint64_t>& work,
                       double loop_share);
/// Sum over the groups of the most loaded processor's work in that group, over the mean
/// load of the whole step (loop_imbalance).
double phased_imbalance(const LoopGroups& lg, const std::vector<std::uint64_t>& work,
                        const std::vector<ProcId>& proc, std::uint32_t k);

/// Places every task with `placed[t]` false, in program order, on the processor that holds
/// most bytes of the data it touches (holders: the processors of placed tasks and of tasks
/// placed before it); ties and no affinity go to the least loaded processor. `proc` holds
/// the placed tasks' processors; `load` is updated with each placed task's work.
void place_by_affinity(const StepGraph& g, const std::vector<std::uint64_t>& work,
                       std::uint32_t k, const std::vector<bool>& placed,
                       std::vector<ProcId>& proc, std::vector<std::uint64_t>& load);

/// Assignment for K >= n: task i on processor i. Empty graph: empty assignment.
Assignment one_task_per_processor(const StepGraph& g, std::uint32_t k);

/// The cases METIS and Scotch must not be given (K = 1 divides by log2(1) in METIS, K >= n
/// returns incomplete partitions, an empty graph): everything on processor 0, or one task
/// per processor, with its edge cut. Empty when the library can be called.
std::optional<Result> library_trivial_case(const StepGraph& g, std::uint32_t k);

/// Maximum-weight perfect matching of a k x k matrix (row-major): row i -> column to[i]
/// maximising the sum of weight[i][to[i]] (Hungarian algorithm, O(k^3)).
std::vector<std::uint32_t> max_weight_assignment(const std::vector<std::int64_t>& weight,
                                                 std::uint32_t k);

/// METIS k-way (serialised behind a process-wide mutex). `part` gets n entries; returns
/// METIS's objval. Requires 2 <= k < n.
std::int64_t metis_kway(const UndirectedGraph& pg, const LibraryWeights& w, std::uint32_t k,
                        const Options& options, std::vector<std::uint32_t>& part);

/// Scotch graph partitioning (serialised). Requires 2 <= k < n.
void scotch_part(const UndirectedGraph& pg, const LibraryWeights& w, std::uint32_t k,
                 const Options& options, std::vector<std::uint32_t>& part);
/// Scotch repartitioning: old[v] = previous part or -1, migration cost per vertex.
void scotch_repart(const UndirectedGraph& pg, const LibraryWeights& w, std::uint32_t k,
                   const Options& options, const std::vector<std::int32_t>& old,
                   const std::vector<std::int32_t>& migration_cost,
                   std::vector<std::uint32_t>& part);

}  // namespace tgraph::partition::detail
