// SPDX-License-Identifier: MIT
// `tgraph simulate --engine simgrid` against the built-in simulator on captures of real
// scenes (measure::capture_trace; tests/partition does not link the engine).
#include <gtest/gtest.h>

#include "tgraph/measure/capture.hpp"
#include "tgraph/model/simulation.hpp"
#include "tgraph/partition/strategy.hpp"

namespace tgraph::partition {
namespace {

#if TGRAPH_HAVE_SIMGRID

// Issue 20's acceptance: on one host (--cluster 1x2) with the same cost model, SimGrid and
// the built-in simulator agree within 1 % on every step of bars64 and falling.
void expect_agreement(const Trace& trace, const char* method, std::uint32_t k) {
  const TracePartition tp = partition_trace(trace, method, k);
  model::SimulatedPlatform p;
  p.cluster = model::ClusterShape{1, k};
  p.model = model::CostModel::defaults();
  const model::Prediction b =
      model::simulate_trace(trace, tp.assignment, model::SimulationEngine::builtin, p);
  const model::Prediction s =
      model::simulate_trace(trace, tp.assignment, model::SimulationEngine::simgrid, p);
  ASSERT_EQ(b.steps.size(), trace.steps.size());
  ASSERT_EQ(s.steps.size(), trace.steps.size());
  for (std::size_t i = 0; i < trace.steps.size(); ++i) {
    const double bm = static_cast<double>(b.steps[i].makespan_ns);
    EXPECT_NEAR(static_cast<double>(s.steps[i].makespan_ns), bm, 0.01 * bm)
        << method << " k " << k << " step " << i;
    EXPECT_EQ(s.steps[i].bytes, b.steps[i].bytes) << "step " << i;
  }
}

TEST(SimgridEngine, AgreesWithinOnePercentWithTheBuiltinSimulatorOnBars64) {
  expect_agreement(measure::capture_trace("bars64", 2), "metis", 2);
}

TEST(SimgridEngine, AgreesWithinOnePercentWithTheBuiltinSimulatorOnFalling) {
  expect_agreement(measure::capture_trace("falling", 60), "metis", 2);
}

#endif  // TGRAPH_HAVE_SIMGRID

}  // namespace
}  // namespace tgraph::partition
