// SPDX-License-Identifier: MIT
// The live run's cost feedback (measure/src/live_observers.hpp): what the partitioner is told.
#include <gtest/gtest.h>

#include <vector>

#include "live_observers.hpp"
#include "tgraph/graph/lowering.hpp"

namespace tgraph::measure::detail {
namespace {

// Two independent tasks on their own data, edges derived.
StepGraph two_tasks() {
  StepGraph g;
  g.kinds = {"op"};
  g.data.push_back({"a", kNoObject, 64});
  g.data.push_back({"b", kNoObject, 64});
  for (DatumId d = 0; d < 2; ++d) {
    const std::vector<Access> acc{{d, AccessMode::W}};
    g.add_task(0, kNoObject, acc, 1, 100 + d);
  }
  g.derive_edges();
  return g;
}

// Runs exec task `t` on thread 0 for each duration in `ns`, back to back.
void run(CostObserver& c, TaskId t, const std::vector<std::int64_t>& ns) {
  std::int64_t at = 0;
  for (std::int64_t d : ns) {
    c.on_begin(0, t, 0, at);
    c.on_end(0, t, 0, at + d);
    at += d + 10;
  }
}

TEST(CostObserver, LeavesTheLongestSampleOutFromThreeOnAndAveragesWithThePreviousStep) {
  StepGraph g = two_tasks();
  const ExecGraph exec = lower(g, nullptr, CwMode::kReduce);
  CostObserver c;
  c.on_step_begin(exec, 1, 0);
  // Task 0: seven 10 us instances, one preempted for 4 ms; task 1: two instances.
  run(c, exec.exec_of[0], {10000, 10000, 4010000, 10000, 10000, 10000, 10000});
  run(c, exec.exec_of[1], {10000, 30000});
  StepGraph next = g;
  c.apply(g, next);  // first measurement: g's costs are 1, the samples are taken as they are
  EXPECT_EQ(next.tasks[0].cost_ns, 10000u);  // not (6 x 10 + 4010) / 7 = 581 us
  EXPECT_EQ(next.tasks[1].cost_ns, 20000u);  // two samples: their mean
  // The next step, same structure: half weight to the new sample.
  c.on_step_begin(exec, 1, 0);
  run(c, exec.exec_of[0], {30000, 30000, 30000});
  run(c, exec.exec_of[1], {20000});
  StepGraph after = next;
  c.apply(next, after);
  EXPECT_EQ(after.tasks[0].cost_ns, 20000u);
  EXPECT_EQ(after.tasks[1].cost_ns, 20000u);
}

}  // namespace
}  // namespace tgraph::measure::detail
