// SPDX-License-Identifier: MIT
// The graph the partition executors run, as a trace the simulators take, and a simulation of a
// trace file's steps, lowered or not (simulate_command).
#pragma once

#include <string>

#include "tgraph/graph/assignment.hpp"
#include "tgraph/graph/trace.hpp"
#include "tgraph/partition/simulation.hpp"
#include "tgraph/partition/strategy.hpp"

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

/// partition::simulate_trace of `trace` under `assignment`, lowered first when `lower` (then
/// Prediction::lowered is set).
partition::Prediction simulate(const Trace& trace, const TraceAssignment& assignment,
                               partition::SimulationEngine engine,
                               const partition::SimulatedPlatform& platform, bool lower);

/// What a simulation of a trace file predicts and how it reports.
struct SimulateCommand {
  std::string trace;       ///< the .tgt file
  std::string assignment;  ///< the .tga file
  partition::SimulationEngine engine = partition::SimulationEngine::builtin;
  std::string platform;  ///< a SimGrid platform file (simgrid engine only), or empty
  std::string cluster;   ///< an N x C cluster as "NxC" (partition::parse_cluster), or empty
  partition::IntraNodeTransfer intra_node = partition::IntraNodeTransfer::reader;
  partition::NamedOptions model;  ///< the cost model (model, calibration)
  bool lower = false;             ///< simulate the lowered graph (simulate)
  partition::SerialWork serial;   ///< the main thread's work per step (builtin engine only)
  bool json = false;              ///< report as one JSON line (else text)
};

/// Reads the files, simulates every step (simulate) and returns the report, ready to print:
/// prediction_json and a newline, or prediction_text. OptionError for a platform file with
/// the builtin engine or serial work with another; InputError for the files.
std::string simulate_command(const SimulateCommand& command);

}  // namespace tgraph::measure
