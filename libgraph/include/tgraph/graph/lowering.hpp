// SPDX-License-Identifier: MIT
// The graph an executor actually runs: cumulative writes made safe for threads (a graph
// transformation: the executors, the simulators and the MPI replay lower alike).
#pragma once

#include <cstdint>
#include <limits>
#include <optional>
#include <string_view>
#include <vector>

#include "tgraph/graph/assignment.hpp"
#include "tgraph/graph/incremental.hpp"
#include "tgraph/graph/step_graph.hpp"

namespace tgraph {

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

inline constexpr std::uint32_t kNoReduction = std::numeric_limits<std::uint32_t>::max();

/// A reducer task: target += temps[0] + temps[1] + ... (in this fixed order), then each
/// temporary is reset to zero for its next use.
struct Reduction {
  DatumId target = 0;          ///< exec datum id (same as the original)
  std::vector<DatumId> temps;  ///< exec datum ids, in increasing processor order
};

/// A step graph after lowering, with the maps back to the original step.
///
/// Paper section 3.2: "cumulative writes by tasks on different processors go to temporary
/// copies, and a reduction task is added". Lowering with CwMode::kReduce does exactly that
/// for every group of consecutive CW writers of one datum whose writers may run on
/// different threads. ReduceScope::kPerProcessor (partition): writers off the group's home
/// processor (the first writer's) write a per-processor temporary, and a `reduce` task on
/// the home processor adds them in processor order. ReduceScope::kPerWriter (work stealing,
/// barrier, StarPU: any writer may run on any thread): the first writer adds into the
/// datum itself, every later writer into a temporary of its own, and the `reduce` task adds
/// the temporaries in program order, so the result does not depend on the threads.
/// ReduceScope::kPerThread (the dynamic policies as their users write them): every writer
/// adds into the temporary of the thread that runs it, one per thread (a block of
/// consecutive exec data, reached through datum_on()), and the `reduce` task adds them in
/// thread order: bounded memory, and the grouping of the writers is the run's.
/// CwMode::kSerialize turns every CW into RW instead (writers in program order).
struct ExecGraph {
  StepGraph graph;                       ///< edges derived
  std::vector<TaskId> origin;            ///< exec task -> original task (kNoTask: reducer)
  std::vector<std::uint32_t> reduction;  ///< exec task -> index in reductions, or kNoReduction
  std::vector<Reduction> reductions;
  std::vector<DatumId> datum_origin;       ///< exec datum -> original datum (a temp: its target)
  std::vector<TaskId> exec_of;             ///< original task -> exec task
  Assignment assignment;                   ///< the assignment on exec tasks (k = 1 when none)
  CwMode cw = CwMode::kReduce;             ///< how CW groups were lowered
  ReduceScope scope = ReduceScope::kNone;  ///< temporaries used by kReduce
  /// Lowering added dependencies the original graph did not have (a CW writer made RW).
  bool added_edges = false;
  /// kPerThread: the temporaries of each lowered group (the executor's threads); else 0.
  std::uint32_t thread_temps = 0;

  /// The exec datum that a task's access of exec datum `d` reaches when it runs on executor
  /// thread `thread`: under kPerThread a writer's access names the first temporary of its
  /// group's block and reaches its thread's; any other access reaches `d` itself.
  DatumId datum_on(DatumId d, std::uint32_t thread) const {
    return thread_temps != 0 && datum_origin[d] != d ? d + thread : d;
  }
};

/// Lowers `g` (edges derived) for assignment `a` (nullptr: everything on processor 0).
/// With kReduce and kPerProcessor, reducers are only needed where a CW group spans
/// processors; with kPerWriter, wherever a group has two writers or more. `reducible`
/// (optional, by original datum) marks the data whose CW groups may use temporaries; the
/// groups of other data are serialised (live bodies that cannot be redirected). `deriver`
/// (optional) derives the exec graph's edges from those of the exec graph it derived last
/// (same edges as from scratch, faster after a small change). `threads`: the executor's
/// thread count, the temporaries per group under kPerThread (1: none needed, nothing lowered).
ExecGraph lower(const StepGraph& g, const Assignment* a, CwMode mode, ReduceScope scope,
                const std::vector<bool>* reducible = nullptr, EdgeDeriver* deriver = nullptr,
                std::uint32_t threads = 1);
/// Same with the scope implied by `a`: kPerProcessor with an assignment, else kNone.
ExecGraph lower(const StepGraph& g, const Assignment* a, CwMode mode);

}  // namespace tgraph
