// SPDX-License-Identifier: MIT
#include "tgraph/measure/lowered.hpp"

#include <algorithm>

#include "tgraph/replay/lowering.hpp"

namespace tgraph::measure {

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
    replay::ExecGraph x = replay::lower(trace.steps[s], &a, replay::CwMode::kReduce,
                                        replay::ReduceScope::kPerProcessor);
    x.graph.host_ns = trace.steps[s].host_ns;
    x.assignment.k = assignment.k;
    out.trace.steps.push_back(std::move(x.graph));
    out.assignment.steps.push_back(std::move(x.assignment));
  }
  out.assignment.partition_ms.resize(steps);
  return out;
}

partition::Prediction simulate(const Trace& trace, const TraceAssignment& assignment,
                               partition::SimulationEngine engine,
                               const partition::SimulatedPlatform& platform, bool lower) {
  if (!lower) return partition::simulate_trace(trace, assignment, engine, platform);
  const LoweredTrace low = lower_trace(trace, assignment);
  partition::Prediction r = partition::simulate_trace(low.trace, low.assignment, engine, platform);
  r.lowered = true;
  return r;
}

}  // namespace tgraph::measure
