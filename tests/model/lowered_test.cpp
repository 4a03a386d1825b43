// SPDX-License-Identifier: MIT
// The lowered trace the simulators take for `tgraph simulate --lower`: a cumulative write
// spread over processors goes through its reducer (two hops), as the executors run it.
#include <gtest/gtest.h>

#include "tgraph/model/simulate.hpp"
#include "tgraph/model/simulator.hpp"

namespace tgraph::model {
namespace {

// Two CW writers of s (costs 10) on processors 0 and 1, then a reader of s (cost 10) on
// processor 2, for two steps (host time 5 in the second).
struct CwSpread {
  Trace trace;
  TraceAssignment assignment;
};

CwSpread spread() {
  StepGraph g;
  g.intern_kind("k");
  g.data = {{"s", kNoObject, 8}};
  const Access cw[] = {{0, AccessMode::CW}};
  const Access r[] = {{0, AccessMode::R}};
  g.add_task(0, kNoObject, cw, 10);
  g.add_task(0, kNoObject, cw, 10);
  g.add_task(0, kNoObject, r, 10);
  g.derive_edges();
  CwSpread s;
  s.trace.steps = {g, g};
  s.trace.steps[1].host_ns = 5;
  Assignment a;
  a.k = 3;
  a.proc = {0, 1, 2};
  s.assignment.k = 3;
  s.assignment.method = "test";
  s.assignment.steps = {a, a};
  return s;
}

model::CostModel latency(double ns) {
  model::CostModel m = model::CostModel::ideal();
  m.sync_latency_ns = ns;
  return m;
}

TEST(LowerTrace, ACumulativeWriteOverProcessorsGoesThroughItsReducer) {
  const CwSpread s = spread();
  const LoweredTrace low = lower_trace(s.trace, s.assignment);
  ASSERT_EQ(low.trace.steps.size(), 2u);
  ASSERT_EQ(low.assignment.steps.size(), 2u);
  EXPECT_EQ(low.assignment.k, 3u);
  const StepGraph& x = low.trace.steps[0];
  ASSERT_EQ(x.tasks.size(), 4u);  // the writers, the reducer, the reader
  const Assignment& a = low.assignment.steps[0];
  TaskId reducer = kNoTask;
  for (TaskId t = 0; t < x.tasks.size(); ++t)
    if (x.kind_name(t) == "reduce") reducer = t;
  ASSERT_NE(reducer, kNoTask);
  EXPECT_EQ(a.proc[reducer], 0u);  // the first writer's processor
  EXPECT_EQ(x.data.size(), 2u);    // s and processor 1's temporary
  EXPECT_EQ(low.trace.steps[1].host_ns, 5u);
  // Unlowered: the reader waits for each writer, one hop: 10 + 100, runs to 120.
  EXPECT_EQ(model::simulate(s.trace.steps[0], s.assignment.steps[0], latency(100)).makespan_ns,
            120u);
  // Lowered: processor 1's temporary reaches the reducer at 110, the sum the reader at 210.
  EXPECT_EQ(model::simulate(x, a, latency(100)).makespan_ns, 220u);
}

TEST(LowerTrace, AGroupOnOneProcessorIsUnchanged) {
  CwSpread s = spread();
  for (Assignment& a : s.assignment.steps) a.proc = {1, 1, 0};
  const LoweredTrace low = lower_trace(s.trace, s.assignment);
  EXPECT_EQ(low.trace.steps[0].tasks.size(), 3u);
  EXPECT_EQ(model::simulate(low.trace.steps[0], low.assignment.steps[0], latency(100)).makespan_ns,
            model::simulate(s.trace.steps[0], s.assignment.steps[0], latency(100)).makespan_ns);
}

}  // namespace
}  // namespace tgraph::model
