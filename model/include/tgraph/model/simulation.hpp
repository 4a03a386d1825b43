// SPDX-License-Identifier: MIT
// `tgraph simulate`: the predicted makespan of every step of a trace under an assignment,
// from the built-in simulator or from SimGrid on a simulated cluster.
#pragma once

#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "tgraph/graph/assignment.hpp"
#include "tgraph/graph/trace.hpp"
#include "tgraph/model/cost_model.hpp"
#include "tgraph/model/platform.hpp"

namespace tgraph::model {

/// Which simulator predicts the schedule.
enum class SimulationEngine {
  builtin,  ///< tgraph::model::simulate (one machine, the cost model; fast)
  simgrid,  ///< SimGrid 3.32 s4u activities on a platform's hosts and links
};
/// "builtin" or "simgrid".
std::string to_string(SimulationEngine e);
/// Whether this build has the SimGrid engine (Debian libsimgrid-dev found by pkg-config).
bool simgrid_available();

/// Who pays for the bytes of a transfer between two cores of one node (SimGrid engine).
enum class IntraNodeTransfer {
  /// The reading core, size / loopback bandwidth of its own time, once per datum version
  /// (cache misses: what the built-in simulator and `tgraph calibrate` measure); the
  /// loopback link carries the signal (its latency).
  reader,
  /// The loopback link, latency + size / bandwidth, overlapping the reader's other work.
  link,
};
/// "reader" or "link".
std::string to_string(IntraNodeTransfer t);

/// Where the processors of a simulation live: a SimGrid platform file or an N x C cluster
/// made from the cost model (platform_xml()).
///
///   SimulatedPlatform p;
///   p.cluster = ClusterShape{4, 16};                 // or p.file = "P.xml"
///   Prediction r = simulate_trace(trace, assignment, SimulationEngine::simgrid, p);
struct SimulatedPlatform {
  std::string file;                     ///< a platform file P.xml (SimGrid engine only), or empty
  std::optional<ClusterShape> cluster;  ///< an N x C cluster, or none
  CostModel model;                      ///< the built-in engine's costs; the links of `cluster`
  IntraNodeTransfer intra_node = IntraNodeTransfer::reader;  ///< simgrid: who pays bytes in a node
  /// Built-in engine: the main thread's serial work before each step's tasks (ns per step,
  /// replacing the trace's host time; load_serial_work); empty: the host time.
  std::vector<std::uint64_t> serial_ns;
};

/// One step's prediction.
struct StepPrediction {
  std::uint64_t makespan_ns = 0;
  std::uint64_t messages =
      0;                    ///< builtin: (version, receiving processor) waits; simgrid: transfers
  std::uint64_t bytes = 0;  ///< datum bytes read from another processor's writes
  std::uint64_t inter_node_messages = 0;  ///< simgrid: transfers between two nodes
  std::uint64_t inter_node_bytes = 0;     ///< simgrid: their bytes
  friend bool operator==(const StepPrediction&, const StepPrediction&) = default;
};

/// What simulate_trace() predicts for a trace.
struct Prediction {
  SimulationEngine engine = SimulationEngine::builtin;
  std::vector<StepPrediction> steps;
  std::uint64_t makespan_ns = 0;  ///< sum of the steps' makespans
  std::uint32_t k = 0;            ///< processors of the assignment
  std::uint32_t hosts = 0;        ///< hosts of the platform (simgrid; builtin: nodes or 1)
  std::uint64_t cores = 0;        ///< cores of the platform (simgrid; builtin: N x C or k)
  std::string platform;           ///< the platform file, "NxC", or "one machine"
  IntraNodeTransfer intra_node = IntraNodeTransfer::reader;  ///< simgrid: as asked
  double simulation_ms = 0;                                  ///< wall time of the simulation itself
  double task_overhead_ns = 0;     ///< CostModel::task_overhead_ns charged per task instance
  double message_overhead_ns = 0;  ///< CostModel::mpi_message_overhead_ns (SimGrid engine)
  bool lowered = false;            ///< the steps were lowered first (`tgraph simulate`, lowered)
  std::vector<std::string> model_terms;  ///< what the prediction charged (model_terms())
};

/// Simulates every step of `trace` under `a` with `engine`. Steps run one after the other
/// (SimGrid: in one simulation, each step starting when the previous one has finished).
/// Processor p runs on core p % C of node p / C of a cluster (platform files: hosts in
/// natural name order, each contributing its cores). The built-in engine ignores the
/// platform's links (every processor a core of one machine with `platform.model`'s costs).
/// Throws UsageError when the SimGrid engine is not built or given no platform, InputError
/// naming the platform file when SimGrid cannot load it, Error when `a` needs more
/// processors than the platform has or its order deadlocks.
Prediction simulate_trace(const Trace& trace, const TraceAssignment& a, SimulationEngine engine,
                          const SimulatedPlatform& platform);

/// The JSON of `tgraph simulate`: engine, makespan_ns, per_step[{step, makespan_ns, ...}], ...
std::string prediction_json(const Prediction& p);
/// `tgraph simulate`'s text report: one line in total, then one per step.
std::string prediction_text(const Prediction& p);

namespace detail {
/// The SimGrid engine (simgrid_engine.cpp): runs in a child process, since SimGrid allows one
/// engine per process and aborts on some bad platform files.
Prediction simgrid_predict(const Trace& trace, const TraceAssignment& a,
                           const SimulatedPlatform& platform);
}  // namespace detail

}  // namespace tgraph::model
