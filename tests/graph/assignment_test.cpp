// SPDX-License-Identifier: MIT
// validate(graph, assignment, k): the one check every consumer of an assignment runs.
#include "tgraph/graph/assignment.hpp"

#include <gtest/gtest.h>

namespace tgraph {
namespace {

StepGraph three_tasks() {
  StepGraph g;
  g.kinds = {"op"};
  g.data = {{"x", kNoObject, 8}};
  const Access w[] = {{0, AccessMode::W}}, r[] = {{0, AccessMode::R}};
  g.add_task(0, kNoObject, w, 1);
  g.add_task(0, kNoObject, r, 1);
  g.add_task(0, kNoObject, r, 1);
  g.derive_edges();
  return g;
}

TEST(Validate, AcceptsAssignmentsWithAndWithoutOrder) {
  const StepGraph g = three_tasks();
  Assignment a{2, {0, 1, 0}, {}};
  EXPECT_EQ(validate(g, a, 2), "");
  a.order = {{2, 0}, {1}};
  EXPECT_EQ(validate(g, a, 2), "");
  StepGraph empty;
  EXPECT_EQ(validate(empty, Assignment{4, {}, {}}, 4), "");
}

TEST(Validate, NamesWhatIsWrong) {
  const StepGraph g = three_tasks();
  auto why = [&](const Assignment& a, std::uint32_t k) { return validate(g, a, k); };
  EXPECT_EQ(why({2, {0, 1, 0}, {}}, 0), "k must be at least 1");
  EXPECT_EQ(why({2, {0, 1, 0}, {}}, 3), "assignment has k = 2, expected 3");
  EXPECT_EQ(why({2, {0, 1}, {}}, 2), "assignment covers 2 tasks, the step has 3");
  EXPECT_EQ(why({2, {0, 2, 0}, {}}, 2), "assignment puts task 1 on processor 2 >= k = 2");
  EXPECT_EQ(why({2, {0, 1, 0}, {{0, 2}}}, 2), "assignment order has 1 processors, k = 2");
  EXPECT_EQ(why({2, {0, 1, 0}, {{0, 7}, {1}}}, 2),
            "assignment order of processor 0 lists task 7, the step has 3");
  EXPECT_EQ(why({2, {0, 1, 0}, {{0, 1}, {1}}}, 2),
            "assignment order of processor 0 lists task 1, which is on processor 1");
  EXPECT_EQ(why({2, {0, 1, 0}, {{0, 0, 2}, {1}}}, 2),
            "assignment order of processor 0 lists task 0 twice");
  EXPECT_EQ(why({2, {0, 1, 0}, {{0}, {1}}}, 2), "assignment order lists 2 of 3 tasks");
}

// x (8 B) written on p0 and read in a 2-iteration loop on p1, which updates y (100 B) that
// the loop's p0 part reads; the break reads the condition the p0 part writes.
TEST(QuotientGraph, SumsLoadsAndSplitsTheCutByProcessorPair) {
  StepGraph g;
  g.kinds = {"op"};
  g.data = {{"x", kNoObject, 8}, {"y", kNoObject, 100}, {"c", kNoObject, 1}};
  const Access w_x[] = {{0, AccessMode::W}};
  const Access update[] = {{0, AccessMode::R}, {1, AccessMode::RW}};
  const Access check[] = {{1, AccessMode::R}, {2, AccessMode::W}};
  const Access brk[] = {{2, AccessMode::R}};
  g.add_task(0, kNoObject, w_x, 5);     // 0 p0
  g.add_task(0, kNoObject, update, 3);  // 1 p1, loop
  g.add_task(0, kNoObject, check, 1);   // 2 p0, loop
  g.add_task(0, kNoObject, brk, 1);     // 3 p0, loop (the break)
  for (TaskId t = 1; t < 4; ++t) g.tasks[t].loop = 0;
  g.loops.push_back({2, 1, 4, 2, 10});
  g.derive_edges();
  const QuotientGraph q = quotient_graph(g, Assignment{2, {0, 1, 0, 0}, {}});
  EXPECT_EQ(q.load_ns, (std::vector<std::uint64_t>{5 + 2 * 1 + 2 * 1, 2 * 3}));
  EXPECT_EQ(q.tasks, (std::vector<std::uint64_t>{3, 1}));
  // p0 -> p1: x (0 -> 1) and, carried, y read by 2 before 1 rewrites it next iteration;
  // p1 -> p0: y (1 -> 2).
  ASSERT_EQ(q.edges.size(), 2u);
  EXPECT_EQ(q.edges[0], (QuotientEdge{0, 1, 1, 1, 8 + 100, 0}));
  EXPECT_EQ(q.edges[1], (QuotientEdge{1, 0, 1, 0, 100, 0}));
  // Everything on one processor: no edge, all the work on it.
  const QuotientGraph one = quotient_graph(g, Assignment{3, {2, 2, 2, 2}, {}});
  EXPECT_TRUE(one.edges.empty());
  EXPECT_EQ(one.load_ns, (std::vector<std::uint64_t>{0, 0, 15}));
}

}  // namespace
}  // namespace tgraph
