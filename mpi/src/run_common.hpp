// SPDX-License-Identifier: MIT
// What both distributed policies share (replay.cpp: tgraph's own schedule over MPI;
// starpu_replay.cpp: StarPU-MPI as the peer): the layout and per-step assignment checks, the
// lowered plans kept across steps, the detection of a repartition, the sums gathered at rank
// 0 and the sequential reference with its checksum. Private to tgraph::mpi.
#pragma once

#include <cstdint>
#include <memory>
#include <unordered_map>
#include <vector>

#include "step_run.hpp"
#include "tgraph/mpi/replay.hpp"

namespace tgraph::mpi {

/// The ranks x threads layout of this run, checked against the assignment and the trace
/// (UsageError otherwise); `steps` gets how many steps to replay.
Layout checked_layout(const Trace& trace, const TraceAssignment& assignment,
                      const MpiReplayOptions& options, std::size_t& steps);

/// Step si's assignment, validated, without an explicit order (each processor runs its
/// tasks in program order).
Assignment step_assignment(const Trace& trace, const TraceAssignment& assignment,
                           std::size_t si, const Layout& layout);

/// Lowered plans (cumulative writes through per-processor reducers), at most kMaxPlans, found
/// again by structure and assignment; every rank evicts the same ones.
class PlanCache {
 public:
  /// The plan of `step` under `a`; `created` says whether it was lowered now.
  Plan& get(const StepGraph& step, const Assignment& a, bool& created);
  /// The plan whose data the workload holds (never evicted).
  Plan* bound = nullptr;

 private:
  std::vector<std::unique_ptr<Plan>> plans_;
};

/// Whether a task that the previous step also had (same stable key) moved to another
/// processor.
class RepartitionWatch {
 public:
  bool moved(const StepGraph& step, const Assignment& a);

 private:
  std::unordered_map<StableKey, ProcId> previous_;
};

/// One step's start, the same for both policies: its plan (lowered now or found again) bound
/// to the workload, every buffer of it touched, `holders` grown to the step's data, tgraph's
/// schedule of the step (the traffic it predicts; `holders` is not advanced) and whether a
/// task moved since the previous step.
struct PreparedStep {
  Plan* plan = nullptr;
  bool rebound = false;  ///< the workload holds another plan's buffers than last step
  StepSchedule schedule;
  bool repartitioned = false;
};
PreparedStep prepare_step(const Trace& trace, const TraceAssignment& assignment, std::size_t si,
                          const Layout& layout, PlanCache& plans, RankWorkload& w,
                          Holders& holders, RepartitionWatch& watch);

/// Every rank at a barrier, then (options.host_work) the step's host work on rank 0 and a
/// barrier; returns when the step began (after the first barrier).
std::int64_t start_step(const StepGraph& step, const MpiReplayOptions& options, RankWorkload& w);

/// Element-wise sum over the ranks, left on rank 0 (the others get zeros).
void sum_to_root(std::vector<std::uint64_t>& v);

/// A barrier that sleeps instead of spinning (ranks idle while rank 0 runs the sequential
/// replay).
void quiet_barrier();

/// The in-cache touch rate every rank's workload uses (rank 0's, broadcast): the words each
/// task touches, and so the final state, must not depend on which process runs it.
double shared_touch_rate();

/// On rank 0: the sequential replay of the same steps and bodies, its per-step and total
/// times, its checksum and, with options.check, whether `result.checksum` equals it. Every
/// rank calls it (a barrier at the end).
void sequential_reference(const Trace& trace, std::size_t steps, const MpiReplayOptions& options,
                          double touch_ns_per_byte, MpiReplayResult& result);

/// replay_distributed under MpiPolicy::kStarpuMpi (starpu_replay.cpp).
MpiReplayResult replay_starpu_mpi(const Trace& trace, const TraceAssignment& assignment,
                                  const MpiReplayOptions& options);

}  // namespace tgraph::mpi
