// SPDX-License-Identifier: MIT
// Replaying a trace under one policy and measuring it against sequential in the same run.
#pragma once

#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "tgraph/graph/assignment.hpp"
#include "tgraph/graph/trace.hpp"
#include "tgraph/measure/step_record.hpp"
#include "tgraph/replay/executor.hpp"
#include "tgraph/replay/observer.hpp"
#include "tgraph/replay/synthetic.hpp"

namespace tgraph::measure {

/// What to replay and how.
struct ReplayOptions {
  replay::Policy policy = replay::Policy::kPartition;
  replay::ExecOptions exec;  ///< threads, spin, pinning, CW mode
  replay::SyntheticOptions synthetic;
  std::uint32_t first_step = 0;
  std::uint32_t steps = 0;   ///< 0: every step from first_step
  std::uint32_t repeat = 3;  ///< timed passes per policy (medians reported)
  /// Also time sequential passes, interleaved (not under the sequential policy itself).
  bool sequential_baseline = true;
  bool observe = true;  ///< one extra pass with observers (busy/wait/idle, locality)
};

/// One step's figures (wall times: medians over the timed passes).
struct StepMeasure : StepRecord {
  std::uint32_t step = 0;
  std::int64_t sequential_wall_ns = 0;
  /// Median over passes of each pass's wall time minus that pass's own plan build.
  std::int64_t run_ns = 0;
  std::uint64_t signals = 0, waits = 0, blocked_waits = 0, parks = 0;
  std::int64_t wait_ns = 0;
  std::uint64_t remote_bytes = 0, migrated_bytes = 0;  ///< from the observed pass
  std::uint64_t work_ns = 0, span_ns = 0;
  /// The step's host time (StepGraph::host_ns), spun on the calling thread before each run of
  /// the step and counted in wall_ns, sequential_wall_ns and run_ns.
  std::uint64_t host_ns = 0;
  std::optional<std::uint64_t> predicted_makespan_ns;
};

/// The whole replay.
struct ReplayResult {
  replay::Policy policy = replay::Policy::kPartition;
  std::uint32_t threads = 1;  ///< ExecOptions::threads; 1 for the sequential policy
  CwMode cw = CwMode::kReduce;             ///< how CW groups ran
  ReduceScope scope = ReduceScope::kNone;  ///< where their temporaries lived
  std::vector<StepMeasure> steps;
  std::int64_t wall_ns = 0;             ///< median over passes of the pass total
  std::int64_t sequential_wall_ns = 0;  ///< same for sequential
  std::vector<std::int64_t> pass_wall_ns, sequential_pass_wall_ns;
  double speedup = 0;     ///< sequential_wall_ns / wall_ns
  double bound = 1;       ///< min(threads, work / span)
  double efficiency = 0;  ///< speedup / bound
  std::uint64_t work_ns = 0, span_ns = 0;
  std::uint64_t host_ns = 0;  ///< sum of the steps' host times (StepMeasure::host_ns)
  /// The observed pass's lost time by cause, summed over the steps (StepRecord::attribution).
  std::optional<explain::Attribution> attribution;
  std::uint64_t plans_built = 0;
  std::uint64_t order_fallbacks = 0;  ///< see Executor::order_fallbacks
  std::optional<std::uint64_t> cache_misses;
  std::string cache_misses_note;
  /// What the caller was warned of (a partitioner's fallback, processors without tasks);
  /// filled by the caller, "warnings" in the JSON.
  std::vector<std::string> warnings;
  replay::SyntheticCalibration calibration;  ///< the synthetic bodies' speed on this machine
  double touch_ns_per_byte = 0;         ///< the bodies' data passes in place (ns per byte)
  double spin_offset_ns = 0;            ///< taken off each body's spin (measured in place)
  std::uint64_t working_set_bytes = 0;  ///< bytes of the first replayed step's data
  std::uint64_t signals() const;
  std::uint64_t waits() const;
  std::int64_t wait_ns() const;
  std::int64_t build_ns() const;
  std::int64_t rebuild_ns() const;
  std::uint64_t remote_bytes() const;
  std::uint64_t migrated_bytes() const;
  std::optional<std::uint64_t> predicted_makespan_ns() const;
};

/// Replays steps of `trace` with synthetic bodies under `options.policy`, timing
/// `options.repeat` passes of it and of sequential, interleaved (pass by pass) so that both
/// see the same machine noise. `assignments` (one per step) is required for the partition
/// policy. `predicted` (optional, per step) is the evaluator's makespan shown beside the
/// measured one. A `timeline` observer, if given, records the observed pass.
ReplayResult replay_trace(const Trace& trace, const TraceAssignment* assignments,
                          const ReplayOptions& options,
                          const std::vector<std::uint64_t>* predicted = nullptr,
                          replay::TimelineObserver* timeline = nullptr);

}  // namespace tgraph::measure
