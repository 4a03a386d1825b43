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

}  // namespace
}  // namespace tgraph
