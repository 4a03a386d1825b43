// SPDX-License-Identifier: MIT
// `tgraph simulate`'s pipeline: the graph the partition executors run, as a trace the
// simulators take, and a simulation of a trace's steps, lowered or not, with its report.
#pragma once

#include <string>

#include "tgraph/graph/assignment.hpp"
#include "tgraph/graph/trace.hpp"
#include "tgraph/model/cost_model.hpp"
#include "tgraph/model/simulation.hpp"

namespace tgraph::model {

/// A trace and its assignment, lowered.
struct LoweredTrace {
  Trace trace;
  TraceAssignment assignment;
};

/// Every step of `trace` lowered for its assignment as the partition executors lower it
/// (threads and `tgraph-mpi replay`: tgraph::lower, CwMode::kReduce,
/// ReduceScope::kPerProcessor, each processor in program order): a cumulative-write group
/// that spans processors becomes per-processor temporaries that its writers off the home
/// processor (the first writer's) write, and a `reduce` task (recorded cost 0) on the home
/// processor that adds them, which the group's readers then read. Simulating the result
/// charges the reduction's two hops (temporaries to the reducer, the sum to the readers)
/// where the step graph has one (each reader after each writer). Steps keep their host
/// time; steps beyond the assignment's are dropped.
LoweredTrace lower_trace(const Trace& trace, const TraceAssignment& assignment);

/// simulate_trace of `trace` under `assignment`, lowered first when `lower` (then
/// Prediction::lowered is set).
Prediction simulate(const Trace& trace, const TraceAssignment& assignment, SimulationEngine engine,
                    const SimulatedPlatform& platform, bool lower);

/// What a simulation of a trace file predicts and how it reports.
struct SimulateCommand {
  std::string trace;       ///< the .tgt file
  std::string assignment;  ///< the .tga file
  SimulationEngine engine = SimulationEngine::builtin;
  std::string platform;  ///< a SimGrid platform file (simgrid engine only), or empty
  std::string cluster;   ///< an N x C cluster as "NxC" (parse_cluster), or empty
  IntraNodeTransfer intra_node = IntraNodeTransfer::reader;
  CostModel model = CostModel::defaults();  ///< the cost model (select_cost_model)
  bool lower = false;                       ///< simulate the lowered graph (simulate)
  SerialWork serial;                        ///< the main thread's work per step (builtin only)
  bool json = false;                        ///< report as one JSON line (else text)
};

/// The platform `command` describes: its cost model, cluster and platform file. OptionError
/// for a malformed cluster or a platform file with the builtin engine. Checked before the
/// files are read.
SimulatedPlatform simulated_platform(const SimulateCommand& command);

/// Simulates every step of `trace` (the file command.trace, read) under `assignment` (the
/// file command.assignment, read and checked against it) on `platform` (simulated_platform)
/// and returns the report, ready to print: prediction_json and a newline, or
/// prediction_text. UsageError for serial work with another engine than the builtin one.
std::string simulate_command(const SimulateCommand& command, const SimulatedPlatform& platform,
                             const Trace& trace, const TraceAssignment& assignment);

}  // namespace tgraph::model
