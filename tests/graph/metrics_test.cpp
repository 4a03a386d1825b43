// SPDX-License-Identifier: MIT
// Work, span with loops unrolled, parallelism.
#include <gtest/gtest.h>

#include "tgraph/graph/metrics.hpp"

namespace tgraph {
namespace {

using M = AccessMode;

StepGraph loop_graph(bool with_independent_task) {
  StepGraph g;
  g.kinds = {"op", "loop.break"};
  g.data = {{"x", kNoObject, 8}, {"cond", kNoObject, 1}, {"y", kNoObject, 8}};
  const Access a0[] = {{0, M::W}};
  g.add_task(0, kNoObject, a0, 5);  // 0
  const Access a1[] = {{0, M::RW}, {1, M::W}};
  g.add_task(0, kNoObject, a1, 2);  // 1: loop body
  const Access a2[] = {{1, M::R}};
  g.add_task(1, kNoObject, a2, 1);  // 2: break
  g.tasks[1].loop = g.tasks[2].loop = 0;
  g.loops.push_back({1, 1, 3, 3, 100});
  const Access a3[] = {{0, M::R}};
  g.add_task(0, kNoObject, a3, 4);  // 3
  if (with_independent_task) {
    const Access a4[] = {{2, M::W}};
    g.add_task(0, kNoObject, a4, 20);  // 4
  }
  g.derive_edges();
  return g;
}

TEST(Metrics, SpanUnrollsLoopIterationsBehindTheBreak) {
  const StepGraph g = loop_graph(false);
  ASSERT_EQ(g.validate(), "");
  // 0 ends at 5; iterations end their break at 8, 11, 14; body task 1 of the last
  // iteration ends at 13; task 3 reads x: 13 + 4 = 17.
  EXPECT_EQ(earliest_finish(g), (std::vector<std::uint64_t>{5, 13, 14, 17}));
  const Metrics m = compute_metrics(g);
  EXPECT_EQ(m.work_ns, 5u + 3 * 2 + 3 * 1 + 4);
  EXPECT_EQ(m.span_ns, 17u);
  EXPECT_EQ(m.loops, 1u);
  EXPECT_EQ(m.loop_iterations, 3u);
  EXPECT_DOUBLE_EQ(m.parallelism, 18.0 / 17.0);
  EXPECT_EQ(m.per_kind.at("op"), 3u);
  EXPECT_EQ(m.per_kind.at("loop.break"), 1u);
}

TEST(Metrics, IndependentLongTaskSetsTheSpan) {
  const Metrics m = compute_metrics(loop_graph(true));
  EXPECT_EQ(m.span_ns, 20u);
  EXPECT_EQ(m.work_ns, 38u);
  EXPECT_EQ(m.tasks, 5u);
}

TEST(Metrics, ForkJoinSpanIsLongestBranch) {
  StepGraph g;
  g.kinds = {"op"};
  for (int i = 0; i < 4; ++i) g.data.push_back({"d" + std::to_string(i), kNoObject, 8});
  const Access src[] = {{0, M::W}};
  g.add_task(0, kNoObject, src, 1);
  for (DatumId d = 1; d <= 3; ++d) {
    const Access acc[] = {{0, M::R}, {d, M::W}};
    g.add_task(0, kNoObject, acc, 10 * d);
  }
  const Access join[] = {{1, M::R}, {2, M::R}, {3, M::R}};
  g.add_task(0, kNoObject, join, 1);
  g.derive_edges();
  const Metrics m = compute_metrics(g);
  EXPECT_EQ(m.span_ns, 1u + 30 + 1);
  EXPECT_EQ(m.work_ns, 1u + 10 + 20 + 30 + 1);
  EXPECT_EQ(m.edges, 6u);
}

TEST(UnitMetrics, CountTasksOnTheCriticalPathWithLoopsUnrolled) {
  // Unit costs: 0 ends at 1; iterations end their break at 3, 5, 7; body task 1 of the last
  // iteration ends at 6; task 3 reads x: 7. Work: 1 + 3 x 2 + 1 = 8 task runs.
  const UnitMetrics u = compute_unit_metrics(loop_graph(false));
  EXPECT_EQ(u.span_tasks, 7u);
  EXPECT_EQ(u.work_tasks, 8u);
  EXPECT_DOUBLE_EQ(u.parallelism, 8.0 / 7.0);
  // The independent task costs 20 ns and sets the timed span, but it is one hop.
  const StepGraph g = loop_graph(true);
  EXPECT_EQ(compute_metrics(g).span_ns, 20u);
  EXPECT_EQ(compute_unit_metrics(g).span_tasks, 7u);
  EXPECT_EQ(compute_unit_metrics(StepGraph{}).parallelism, 0.0);
}

TEST(Metrics, EmptyGraphHasZeroParallelism) {
  StepGraph g;
  g.derive_edges();
  const Metrics m = compute_metrics(g);
  EXPECT_EQ(m.span_ns, 0u);
  EXPECT_EQ(m.parallelism, 0.0);
}

TEST(IncomingEdges, ListsTheEdgesIntoEachTaskInListOrder) {
  const std::vector<Edge> edges = {{0, 2, 0}, {1, 2, 0}, {0, 1, 0}, {2, 3, 0}, {0, 3, 0}};
  const IncomingEdges in = incoming_edges(5, edges);
  EXPECT_EQ(in.begin, (std::vector<std::uint32_t>{0, 0, 1, 3, 5, 5}));
  EXPECT_EQ(in.edge, (std::vector<std::uint32_t>{2, 0, 1, 3, 4}));
}

}  // namespace
}  // namespace tgraph
