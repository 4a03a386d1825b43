// SPDX-License-Identifier: MIT
#include "tgraph/model/simulate.hpp"

#include <algorithm>

#include "tgraph/graph/error.hpp"
#include "tgraph/graph/lowering.hpp"

namespace tgraph::model {

LoweredTrace lower_trace(const Trace& trace, const TraceAssignment& assignment) {
  LoweredTrace out;
  out.trace.header = trace.header;
  out.assignment.method = assignment.method;
  out.assignment.k = assignment.k;
  out.assignment.partition_ms = assignment.partition_ms;
  const std::size_t steps = std::min(trace.steps.size(), assignment.steps.size());
  for (std::size_t s = 0; s < steps; ++s) {
    Assignment a = assignment.steps[s];
    a.order.clear();  // as tgraph-mpi replay: each processor in program order
    ExecGraph x = tgraph::lower(trace.steps[s], &a, CwMode::kReduce, ReduceScope::kPerProcessor);
    x.graph.host_ns = trace.steps[s].host_ns;
    x.assignment.k = assignment.k;
    out.trace.steps.push_back(std::move(x.graph));
    out.assignment.steps.push_back(std::move(x.assignment));
  }
  out.assignment.partition_ms.resize(steps);
  return out;
}

Prediction simulate(const Trace& trace, const TraceAssignment& assignment, SimulationEngine engine,
                    const SimulatedPlatform& platform, bool lower) {
  if (!lower) return simulate_trace(trace, assignment, engine, platform);
  const LoweredTrace low = lower_trace(trace, assignment);
  Prediction r = simulate_trace(low.trace, low.assignment, engine, platform);
  r.lowered = true;
  return r;
}

SimulatedPlatform simulated_platform(const SimulateCommand& c) {
  SimulatedPlatform p;
  p.model = c.model;
  if (!c.cluster.empty()) p.cluster = parse_cluster(c.cluster);
  p.file = c.platform;
  p.intra_node = c.intra_node;
  if (c.engine == SimulationEngine::builtin && !p.file.empty())
    throw OptionError("platform",
                      "the builtin engine has no platform model (use {engine} simgrid)");
  return p;
}

std::string simulate_command(const SimulateCommand& c, const SimulatedPlatform& platform,
                             const Trace& trace, const TraceAssignment& as) {
  SimulatedPlatform p = platform;
  p.serial_ns = c.serial.per_step(trace.steps.size());
  if (!p.serial_ns.empty() && c.engine != SimulationEngine::builtin)
    throw UsageError("",
                     "{live}/{serial_ns}: only the builtin engine charges the main thread's work",
                     kNamesFields);
  const Prediction r = simulate(trace, as, c.engine, p, c.lower);
  return c.json ? prediction_json(r) + "\n" : prediction_text(r);
}

}  // namespace tgraph::model
