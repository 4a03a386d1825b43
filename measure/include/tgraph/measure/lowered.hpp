// SPDX-License-Identifier: MIT
// The graph the partition executors run, as a trace the simulators take, and `tgraph
// simulate [--lower]` on it.
#pragma once

#include "tgraph/graph/assignment.hpp"
#include "tgraph/graph/trace.hpp"
#include "tgraph/partition/simulation.hpp"

namespace tgraph::measure {

/// A trace and its assignment, lowered.
struct LoweredTrace {
  Trace trace;
  TraceAssignment assignment;
};

/// Every step of `trace` lowered for its assignment as the partition executors lower it
/// (threads and `tgraph-mpi replay`: replay::lower, CwMode::kReduce,
/// ReduceScope::kPerProcessor, each processor in program order): a cumulative-write group
/// that spans processors becomes per-processor temporaries that its writers off the home
/// processor (the first writer's) write, and a `reduce` task (recorded cost 0) on the home
/// processor that adds them, which the group's readers then read. Simulating the result
/// charges the reduction's two hops (temporaries to the reducer, the sum to the readers)
/// where the step graph has one (each reader after each writer). Steps keep their host
/// time; steps beyond the assignment's are dropped.
LoweredTrace lower_trace(const Trace& trace, const TraceAssignment& assignment);

/// `tgraph simulate`: partition::simulate_trace of `trace` under `assignment`, lowered first
/// when `lower` (then Prediction::lowered is set).
partition::Prediction simulate(const Trace& trace, const TraceAssignment& assignment,
                               partition::SimulationEngine engine,
                               const partition::SimulatedPlatform& platform, bool lower);

}  // namespace tgraph::measure
