// SPDX-License-Identifier: MIT
// Execution policies of the replay executors (how cumulative writes are lowered: CwMode and
// ReduceScope, tgraph/graph/lowering.hpp).
#pragma once

#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "tgraph/graph/lowering.hpp"

namespace tgraph::replay {

/// How the tasks of a step are put on threads: the identity of a registered policy
/// (replay/src/registry.cpp holds its name, help and factory).
enum class Policy : unsigned char {
  kSequential = 0,  ///< one thread, program order
  kPartition = 1,   ///< one pinned thread per processor of an Assignment, signal/wait
  kWorksteal = 2,   ///< oneTBB, dependency counting over the dataflow graph, no affinity
  kBarrier = 3,     ///< a parallel loop per operation, barriers between them (OpenMP)
  kStarpu = 4,      ///< StarPU tasks with one data handle per datum (implicit dependencies)
  kOmpTasks = 5,    ///< OpenMP tasks with one `depend` object per datum (libgomp)
};

/// What the registry says of a policy.
struct PolicyInfo {
  Policy policy = Policy::kSequential;
  std::string_view name;  ///< its word on the command line and in reports
  std::string_view help;  ///< one line
  bool built = true;      ///< in this build (StarPU's needs libstarpu-dev)
  bool baseline = false;  ///< a run's method of its own, beside the strategies (not partition)
  std::string_view missing;  ///< why a build lacks it ("" when built)
};

/// Every registered policy, in the order the command line lists them.
std::vector<PolicyInfo> policies();
/// The registered name: "partition", "worksteal", "barrier", "starpu", "omp-tasks" or
/// "sequential".
std::string_view to_string(Policy policy);
/// Inverse of to_string; nullopt for an unknown name.
std::optional<Policy> parse_policy(std::string_view name);
/// The registered names, ", " between them and `last` (e.g. "or") before the last one
/// ("" : ", " there too); the baselines only when `baselines_only`.
std::string policy_list(std::string_view last = "", bool baselines_only = false);

/// What one parallel phase of the barrier policy holds (a barrier follows each phase).
enum class BarrierRule : unsigned char {
  /// One phase per dependency level: the topological level of the step's dataflow graph
  /// (longest path from the start of its loop region), as a competent OpenMP user puts each
  /// level in one `omp for`. On the physics scenes it equals the paper's barrier after
  /// every operation; on a graph whose program order interleaves independent kinds it does
  /// not depend on that order.
  kLevel = 0,
  /// One phase per run of consecutive tasks of one kind in program order (the paper's "one
  /// parallel loop per operation"), cut where a task depends on the run.
  kOperation = 1,
  /// As an OpenMP user writes a CG solver (the default): the phases of kOperation, each an
  /// `omp for` with a static schedule (the i-th task of every phase on the same thread),
  /// `nowait` where no task before the next barrier depends on another thread's task since
  /// the last one; a barrier ends every loop iteration.
  kOmpFor = 2,
};

/// "level", "operation" or "omp-for".
std::string_view to_string(BarrierRule rule);
/// Inverse of to_string; nullopt for an unknown name.
std::optional<BarrierRule> parse_barrier_rule(std::string_view name);

}  // namespace tgraph::replay
