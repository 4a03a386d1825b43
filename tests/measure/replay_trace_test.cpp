// SPDX-License-Identifier: MIT
// replay_trace (`tgraph replay`): which passes it times, what it reports per step, its errors.
#include "tgraph/measure/replay_trace.hpp"

#include <gtest/gtest.h>

#include "random_graph.hpp"
#include "tgraph/graph/error.hpp"
#include "tgraph/graph/metrics.hpp"

namespace tgraph::measure {
namespace {

using namespace tgraph::replay;

Trace two_step_trace() {
  Trace t;
  t.steps = {test::random_graph(3), test::random_graph(4)};
  return t;
}

ReplayOptions quick(Policy policy, std::uint32_t threads) {
  ReplayOptions o;
  o.policy = policy;
  o.exec.threads = threads;
  o.exec.pin = false;
  o.synthetic.cost_scale = 0.0;
  o.synthetic.touch = false;
  o.repeat = 2;
  return o;
}

TEST(ReplayTrace, SequentialPolicyRunsOnOneThreadAndIsItsOwnBaseline) {
  const Trace trace = two_step_trace();
  EXPECT_EQ(replay_trace(trace, nullptr, quick(Policy::kSequential, 2000)).threads, 1u);
  const ReplayResult r = replay_trace(trace, nullptr, quick(Policy::kSequential, 4));
  EXPECT_EQ(r.threads, 1u);
  EXPECT_EQ(r.pass_wall_ns.size(), 2u);
  EXPECT_TRUE(r.sequential_pass_wall_ns.empty());  // no separate baseline passes
  EXPECT_EQ(r.sequential_wall_ns, r.wall_ns);      // it is the baseline: speed-up 1
  EXPECT_EQ(r.speedup, 1.0);
  ASSERT_EQ(r.steps.size(), 2u);
  for (std::uint32_t s = 0; s < 2; ++s) {
    const Metrics m = compute_metrics(trace.steps[s]);
    EXPECT_EQ(r.steps[s].step, s);
    EXPECT_EQ(r.steps[s].work_ns, m.work_ns);
    EXPECT_EQ(r.steps[s].span_ns, m.span_ns);
    EXPECT_EQ(r.steps[s].signals, 0u);
  }
}

TEST(ReplayTrace, PartitionPolicyTimesBothAndCarriesThePredictionAndTheTimeline) {
  const Trace trace = two_step_trace();
  TraceAssignment as;
  as.k = 2;
  for (std::uint32_t s = 0; s < 2; ++s)
    as.steps.push_back(test::random_assignment(trace.steps[s], 2, s));
  const std::vector<std::uint64_t> predicted = {1234, 5678};
  TimelineObserver timeline;
  const ReplayResult r =
      replay_trace(trace, &as, quick(Policy::kPartition, 2), &predicted, &timeline);
  EXPECT_EQ(r.threads, 2u);
  EXPECT_EQ(r.pass_wall_ns.size(), 2u);
  EXPECT_EQ(r.sequential_pass_wall_ns.size(), 2u);
  ASSERT_EQ(r.steps.size(), 2u);
  EXPECT_EQ(r.steps[0].predicted_makespan_ns, 1234u);
  EXPECT_EQ(r.steps[1].predicted_makespan_ns, 5678u);
  EXPECT_EQ(r.predicted_makespan_ns(), 1234u + 5678u);
  // The timeline holds the observed pass: every task instance of both steps.
  std::size_t instances = 0;
  for (const StepGraph& g : trace.steps)
    for (TaskId t = 0; t < g.tasks.size(); ++t) instances += g.runs(t);
  std::size_t original = 0;
  for (const TimelineTask& e : timeline.timeline().tasks) original += e.origin.has_value() ? 1 : 0;
  EXPECT_EQ(original, instances);
  EXPECT_EQ(timeline.timeline().tasks.back().step, 1u);
}

TEST(ReplayTrace, RejectsMissingAssignmentsAndZeroThreads) {
  const Trace trace = two_step_trace();
  EXPECT_THROW(replay_trace(trace, nullptr, quick(Policy::kPartition, 2)), UsageError);
  try {
    replay_trace(trace, nullptr, quick(Policy::kWorksteal, 0));
    FAIL() << "no error";
  } catch (const UsageError& e) {
    EXPECT_STREQ(e.what(), "threads: must be at least 1");  // the field; tgraph says --threads
  }
  ReplayOptions o = quick(Policy::kSequential, 1);
  o.first_step = 2;
  EXPECT_THROW(replay_trace(trace, nullptr, o), UsageError);
}

}  // namespace
}  // namespace tgraph::measure
