// SPDX-License-Identifier: MIT
// Dependency extraction checked edge by edge on hand-written sequences.
#include <gtest/gtest.h>

#include <vector>

#include "tgraph/graph/step_graph.hpp"

namespace tgraph {
namespace {

using M = AccessMode;

// Builds a graph over `n_data` anonymous data; tasks are added with t({...}).
struct G {
  StepGraph g;
  explicit G(int n_data) {
    g.kinds = {"op", "loop.break"};
    for (int i = 0; i < n_data; ++i) g.data.push_back({"d" + std::to_string(i), kNoObject, 8});
  }
  TaskId t(std::initializer_list<Access> acc, std::uint64_t cost = 1) {
    std::vector<Access> v(acc);
    return g.add_task(0, kNoObject, v, cost);
  }
  std::vector<Edge> edges() {
    g.derive_edges();
    return g.edges;
  }
};

Edge E(TaskId from, TaskId to, DatumId d, EdgeKind k) { return {from, to, d, k}; }

// The worked example of docs/design.md ("Dependency rules"): x = 0, f = 1.
TEST(Dependencies, DesignDocWorkedExampleGivesTheEdgesItLists) {
  G g(2);
  g.t({{1, M::W}});                // 0 resetForce
  g.t({{0, M::R}, {1, M::CW}});    // 1 springA
  g.t({{0, M::R}, {1, M::CW}});    // 2 springB
  g.t({{1, M::R}, {0, M::RW}});    // 3 integrate
  g.t({{1, M::W}});                // 4 clearForce
  g.t({{1, M::RW}});               // 5 scaleForce
  g.t({{1, M::W}});                // 6 resetForce
  EXPECT_EQ(g.edges(), (std::vector<Edge>{
                           E(0, 1, 1, EdgeKind::WAW), E(0, 2, 1, EdgeKind::WAW),
                           E(1, 3, 0, EdgeKind::WAR), E(1, 3, 1, EdgeKind::RAW),
                           E(2, 3, 0, EdgeKind::WAR), E(2, 3, 1, EdgeKind::RAW),
                           E(3, 4, 1, EdgeKind::WAR), E(4, 5, 1, EdgeKind::RAW),
                           E(5, 6, 1, EdgeKind::WAW)}));
}

TEST(Dependencies, ReadAfterWriteGivesRawEdge) {
  G g(1);
  g.t({{0, M::W}});
  g.t({{0, M::R}});
  EXPECT_EQ(g.edges(), (std::vector<Edge>{E(0, 1, 0, EdgeKind::RAW)}));
}

TEST(Dependencies, ReadsAreIndependentAndWriterWaitsForAllOfThem) {
  G g(1);
  g.t({{0, M::W}});  // 0
  g.t({{0, M::R}});  // 1
  g.t({{0, M::R}});  // 2
  g.t({{0, M::W}});  // 3: WAR from 1 and 2; WAW 0->3 implied, not emitted
  EXPECT_EQ(g.edges(), (std::vector<Edge>{E(0, 1, 0, EdgeKind::RAW), E(0, 2, 0, EdgeKind::RAW),
                                          E(1, 3, 0, EdgeKind::WAR), E(2, 3, 0, EdgeKind::WAR)}));
}

TEST(Dependencies, WriteAfterWriteWithoutReaderGivesWawEdge) {
  G g(1);
  g.t({{0, M::W}});
  g.t({{0, M::W}});
  EXPECT_EQ(g.edges(), (std::vector<Edge>{E(0, 1, 0, EdgeKind::WAW)}));
}

TEST(Dependencies, ReadOfUnwrittenDatumHasNoEdge) {
  G g(1);
  g.t({{0, M::R}});
  g.t({{0, M::R}});
  EXPECT_TRUE(g.edges().empty());
}

TEST(Dependencies, ReadWriteChainsAndWaitsForReaders) {
  G g(1);
  g.t({{0, M::RW}});  // 0
  g.t({{0, M::R}});   // 1
  g.t({{0, M::RW}});  // 2: RAW 0->2, WAR 1->2
  g.t({{0, M::RW}});  // 3: RAW 2->3
  EXPECT_EQ(g.edges(), (std::vector<Edge>{E(0, 1, 0, EdgeKind::RAW), E(0, 2, 0, EdgeKind::RAW),
                                          E(1, 2, 0, EdgeKind::WAR), E(2, 3, 0, EdgeKind::RAW)}));
}

TEST(Dependencies, CumulativeWritersAreIndependentAndAllPrecedeTheReader) {
  G g(1);
  g.t({{0, M::W}});   // 0 reset
  g.t({{0, M::CW}});  // 1
  g.t({{0, M::CW}});  // 2
  g.t({{0, M::CW}});  // 3
  g.t({{0, M::R}});   // 4
  EXPECT_EQ(g.edges(), (std::vector<Edge>{E(0, 1, 0, EdgeKind::WAW), E(0, 2, 0, EdgeKind::WAW),
                                          E(0, 3, 0, EdgeKind::WAW), E(1, 4, 0, EdgeKind::RAW),
                                          E(2, 4, 0, EdgeKind::RAW), E(3, 4, 0, EdgeKind::RAW)}));
}

TEST(Dependencies, CumulativeGroupAfterReadersWaitsForThem) {
  G g(1);
  g.t({{0, M::W}});   // 0
  g.t({{0, M::R}});   // 1
  g.t({{0, M::CW}});  // 2: WAR 1->2
  g.t({{0, M::CW}});  // 3: WAR 1->3
  g.t({{0, M::W}});   // 4: WAW from group members 2, 3
  EXPECT_EQ(g.edges(), (std::vector<Edge>{E(0, 1, 0, EdgeKind::RAW), E(1, 2, 0, EdgeKind::WAR),
                                          E(1, 3, 0, EdgeKind::WAR), E(2, 4, 0, EdgeKind::WAW),
                                          E(3, 4, 0, EdgeKind::WAW)}));
}

TEST(Dependencies, ReaderBetweenTwoCumulativeGroupsSplitsThem) {
  G g(1);
  g.t({{0, M::CW}});  // 0
  g.t({{0, M::R}});   // 1: RAW 0->1
  g.t({{0, M::CW}});  // 2: WAR 1->2 (a new group)
  g.t({{0, M::R}});   // 3: RAW 2->3 only
  EXPECT_EQ(g.edges(), (std::vector<Edge>{E(0, 1, 0, EdgeKind::RAW), E(1, 2, 0, EdgeKind::WAR),
                                          E(2, 3, 0, EdgeKind::RAW)}));
}

TEST(Dependencies, IndependentDataGiveIndependentTasks) {
  G g(2);
  g.t({{0, M::W}});
  g.t({{1, M::W}});
  g.t({{0, M::R}, {1, M::R}});
  EXPECT_EQ(g.edges(), (std::vector<Edge>{E(0, 2, 0, EdgeKind::RAW), E(1, 2, 1, EdgeKind::RAW)}));
}

TEST(Dependencies, TaskNeverDependsOnItself) {
  G g(1);
  g.t({{0, M::R}, {0, M::W}});
  g.t({{0, M::R}});
  EXPECT_EQ(g.edges(), (std::vector<Edge>{E(0, 1, 0, EdgeKind::RAW)}));
}

// A CG-like loop: p read by q = A p, then dot, then update of p at the end.
TEST(Dependencies, LoopBodyGetsIntraAndCarriedEdges) {
  G g(4);  // 0 = p, 1 = q, 2 = cond, 3 = x (outside)
  g.t({{3, M::W}});                          // 0: before the loop
  const TaskId first = 1;
  g.t({{0, M::R}, {1, M::W}});               // 1: q = A p
  g.t({{1, M::R}, {2, M::W}});               // 2: cond = f(q)
  g.t({{1, M::R}, {0, M::RW}, {3, M::R}});   // 3: p = g(p, q, x)
  g.t({{2, M::R}});                          // 4: break
  for (TaskId t = first; t < 5; ++t) g.g.tasks[t].loop = 0;
  g.g.loops.push_back({2, first, 5, 3, 10});
  g.t({{0, M::R}});                          // 5: after the loop
  ASSERT_EQ(g.g.validate(), "");
  EXPECT_EQ(g.edges(),
            (std::vector<Edge>{E(1, 2, 1, EdgeKind::RAW), E(0, 3, 3, EdgeKind::RAW),
                               E(1, 3, 0, EdgeKind::WAR), E(1, 3, 1, EdgeKind::RAW),
                               E(2, 4, 2, EdgeKind::RAW), E(3, 5, 0, EdgeKind::RAW)}));
  // Iteration i -> i+1: q = A p reads the p of 3; rewriting q waits for its readers 2, 3;
  // cond is rewritten after the break read it. 3 -> 3 (its own previous iteration) is
  // implicit and not listed.
  EXPECT_EQ(g.g.carried_edges,
            (std::vector<Edge>{E(2, 1, 1, EdgeKind::WAR), E(3, 1, 0, EdgeKind::RAW),
                               E(3, 1, 1, EdgeKind::WAR), E(4, 2, 2, EdgeKind::WAR)}));
}

TEST(StepGraphValidate, RejectsLoopWhoseLastTaskDoesNotReadCondition) {
  G g(2);
  g.t({{0, M::W}});
  g.t({{1, M::W}});
  g.g.tasks[0].loop = g.g.tasks[1].loop = 0;
  g.g.loops.push_back({0, 0, 2, 1, 5});
  EXPECT_NE(g.g.validate().find("does not read the condition"), std::string::npos);
}

TEST(StepGraphValidate, RejectsOutOfRangeDatum) {
  G g(1);
  g.t({{5, M::R}});
  EXPECT_NE(g.g.validate().find("datum 5 out of range"), std::string::npos);
}

TEST(StructuralHash, IgnoresCostsAndIterationsButNotAccesses) {
  G a(2), b(2), c(2);
  a.t({{0, M::W}}, 10);
  b.t({{0, M::W}}, 99);
  c.t({{1, M::W}}, 10);
  EXPECT_EQ(a.g.structural_hash(), b.g.structural_hash());
  EXPECT_TRUE(a.g.same_structure(b.g));
  EXPECT_NE(a.g.structural_hash(), c.g.structural_hash());
  EXPECT_FALSE(a.g.same_structure(c.g));
}

// same_structure() reads each field of the structure (the executors' plan cache trusts it on
// every step) and nothing else: one change at a time from a two-task loop over two objects.
TEST(StructuralHash, SameStructureSeesEachFieldAndOnlyThose) {
  const auto base = [] {
    StepGraph g;
    g.kinds = {"op", "loop.break"};
    g.objects = {{"a"}, {"b"}};
    g.data = {{"x", 0, 8}, {"cond", kNoObject, 8}};
    const Access t0[] = {{0, M::R}, {1, M::W}};
    const Access t1[] = {{1, M::R}};
    g.add_task(0, 0, t0, 10, 7);
    g.add_task(1, kNoObject, t1, 10, 8);
    for (Task& t : g.tasks) t.loop = 0;
    g.loops.push_back({1, 0, 2, 3, 10});
    return g;
  };
  const StepGraph g = base();
  ASSERT_EQ(g.validate(), "");
  const auto differs = [&](auto&& change) {
    StepGraph h = base();
    change(h);
    return !g.same_structure(h) && !h.same_structure(g);
  };
  EXPECT_FALSE(differs([](StepGraph& h) {
    h.tasks[0].cost_ns = 99;
    h.loops[0].iterations = 9;
  }));
  EXPECT_TRUE(differs([](StepGraph& h) { h.accesses[0].mode = M::RW; }));
  EXPECT_TRUE(differs([](StepGraph& h) { h.accesses[2].datum = 0; }));
  EXPECT_TRUE(differs([](StepGraph& h) { h.tasks[0].kind = 1; }));
  EXPECT_TRUE(differs([](StepGraph& h) { h.tasks[0].object = 1; }));
  EXPECT_TRUE(differs([](StepGraph& h) { h.tasks[1].key = 9; }));
  EXPECT_TRUE(differs([](StepGraph& h) { h.tasks[1].loop = kNoLoop; }));
  EXPECT_TRUE(differs([](StepGraph& h) {
    h.tasks[0].access_count = 1;
    h.tasks[1].access_begin = 1;
    h.tasks[1].access_count = 2;
  }));
  EXPECT_TRUE(differs([](StepGraph& h) { h.data[0].bytes = 16; }));
  EXPECT_TRUE(differs([](StepGraph& h) { h.data[0].object = 1; }));
  EXPECT_TRUE(differs([](StepGraph& h) { h.data[0].name = "y"; }));
  EXPECT_TRUE(differs([](StepGraph& h) { h.data[1].name = "cond2"; }));
  EXPECT_TRUE(differs([](StepGraph& h) { h.objects[1].name = "c"; }));
  EXPECT_TRUE(differs([](StepGraph& h) { h.kinds[0] = "op2"; }));
  EXPECT_TRUE(differs([](StepGraph& h) { h.loops[0].max_iterations = 11; }));
  EXPECT_TRUE(differs([](StepGraph& h) { h.loops[0].first = 1; }));
  EXPECT_TRUE(differs([](StepGraph& h) { h.data.push_back({"z", kNoObject, 8}); }));
  EXPECT_TRUE(differs([](StepGraph& h) { h.objects.push_back({"c"}); }));
}

}  // namespace
}  // namespace tgraph
