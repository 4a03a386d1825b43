// SPDX-License-Identifier: MIT
// Execution policies of the replay executors and how cumulative writes are handled.
#pragma once

#include <optional>
#include <string_view>

namespace tgraph::replay {

/// How the tasks of a step are put on threads.
enum class Policy : unsigned char {
  kSequential = 0,  ///< one thread, program order
  kPartition = 1,   ///< one pinned thread per processor of an Assignment, signal/wait
  kWorksteal = 2,   ///< oneTBB, dependency counting over the dataflow graph, no affinity
  kBarrier = 3,     ///< a parallel loop per operation, barriers between them (OpenMP)
  kStarpu = 4,      ///< StarPU tasks with one data handle per datum (implicit dependencies)
  kOmpTasks = 5,    ///< OpenMP tasks with one `depend` object per datum (libgomp)
};

/// "sequential", "partition", "worksteal", "barrier", "starpu" or "omp-tasks".
std::string_view to_string(Policy policy);
/// Inverse of to_string; nullopt for an unknown name.
std::optional<Policy> parse_policy(std::string_view name);

/// How cumulative (CW) writes by tasks on different threads are made safe.
enum class CwMode : unsigned char {
  kReduce = 0,     ///< per-processor temporaries summed by a reducer task in processor order
  kSerialize = 1,  ///< CW treated as RW: writers run in program order (bit-identical to sequential)
};

/// "reduce" or "serialize".
std::string_view to_string(CwMode mode);

/// Where the temporaries of a CW group whose writers may run on different threads live
/// (CwMode::kReduce).
enum class ReduceScope : unsigned char {
  kNone = 0,          ///< no temporaries: the writers run on one thread (sequential)
  kPerProcessor = 1,  ///< one temporary per processor off the group's home (partition)
  /// One temporary per writer after the group's first, added in program order (the dynamic
  /// policies: any writer may run on any thread, the combine stays deterministic).
  kPerWriter = 2,
  /// One temporary per executor thread for every writer of the group, added in thread order
  /// by the reducer (the dynamic policies as their users write them: oneTBB's
  /// enumerable_thread_specific, OpenMP's `reduction`). Which writers share a temporary is
  /// the run's: the sum is the sequential one within rounding, not bit for bit.
  kPerThread = 3,
};

/// "none", "per-processor", "per-writer" or "per-thread".
std::string_view to_string(ReduceScope scope);
/// Inverse of to_string; nullopt for an unknown name.
std::optional<ReduceScope> parse_reduce_scope(std::string_view name);

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
