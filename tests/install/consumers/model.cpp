// SPDX-License-Identifier: MIT
// tgraph::model: the built-in simulator on the fork-join step, and SimGrid's engine when the
// package was built with it (a library the package must link).
#include <cstdio>

#include "fork_join.hpp"
#include "tgraph/model/simulation.hpp"
#include "tgraph/model/simulator.hpp"

int main() {
  using consumer::expect;
  namespace mdl = tgraph::model;
  const tgraph::StepGraph g = consumer::fork_join();
  // Without costs of its own, two processors: 4 scale tasks each, then the sum.
  tgraph::Assignment a;
  a.k = 2;
  for (std::uint32_t i = 0; i < consumer::kWidth; ++i) a.proc.push_back(i % 2);
  a.proc.push_back(0);
  const mdl::Schedule s = mdl::simulate(g, a, mdl::CostModel::ideal());
  expect(s.makespan_ns == (consumer::kWidth / 2 + 1) * consumer::kCostNs, "ideal makespan");
  std::printf("model builtin: %llu ns\n", static_cast<unsigned long long>(s.makespan_ns));
  if (mdl::simgrid_available()) {
    tgraph::Trace trace;
    trace.steps.push_back(g);
    tgraph::TraceAssignment ta{"consumer", 2, {a}, {0.0}};
    mdl::SimulatedPlatform p;
    p.cluster = mdl::ClusterShape{1, 2};
    p.model = mdl::CostModel::ideal();
    const mdl::Prediction r = mdl::simulate_trace(trace, ta, mdl::SimulationEngine::simgrid, p);
    expect(r.steps.size() == 1 && r.steps[0].makespan_ns >= s.makespan_ns, "simgrid makespan");
    std::printf("model simgrid: %llu ns\n",
                static_cast<unsigned long long>(r.steps[0].makespan_ns));
  }
  return 0;
}
