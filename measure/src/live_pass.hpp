// SPDX-License-Identifier: MIT
// Internal: one pass of a live run (the engine recorded step by step, partitioned, executed).
#pragma once

#include <cstdint>
#include <vector>

#include "tgraph/graph/assignment.hpp"
#include "tgraph/measure/live.hpp"

namespace tgraph::measure::detail {

/// What one pass keeps and feeds beside its timings.
struct PassOptions {
  /// Measure the tasks (sampled) and give their costs to the next step's partitioning.
  bool feed_costs = false;
  bool keep_assignments = false;  ///< PassResult::assignments, one per step
  bool keep_state = false;        ///< PassResult::state after the last step
  /// The assignment of each step instead of the partitioner's (nullptr: the partitioner).
  const std::vector<Assignment>* fixed = nullptr;
  /// Observer already added to the executor whose per-thread figures each step keeps.
  replay::StatsObserver* stats = nullptr;
};

/// What one pass measured.
struct PassResult {
  std::vector<LiveStepMeasure> steps;
  std::int64_t wall_ns = 0;
  std::vector<Assignment> assignments;  ///< PassOptions::keep_assignments
  StateSnapshot state;                  ///< PassOptions::keep_state
  std::uint64_t signals = 0, waits = 0, blocked_waits = 0, parks = 0;
  std::uint64_t longest_reduction = 1;  ///< over the steps recorded (measure::longest_reduction)
};

/// One pass of `options.steps` steps of a fresh engine through `ex`.
PassResult run_pass(const EngineFactory& make_engine, const partition::StepPartitioner* partitioner,
                    replay::Executor& ex, const LiveOptions& options, const PassOptions& pass);

}  // namespace tgraph::measure::detail
