// SPDX-License-Identifier: MIT
// The schedule simulator on schedules computable by hand, and the lower bound on random graphs.
#include "tgraph/model/simulator.hpp"

#include <gtest/gtest.h>

#include "test_graphs.hpp"
#include "test_model.hpp"
#include "tgraph/graph/error.hpp"
#include "tgraph/graph/metrics.hpp"
#include "tgraph/partition/strategy.hpp"

namespace tgraph::model {
namespace {

using namespace tgraph::partition;  // the strategies that place the tasks

using namespace partition::testing;  // Builder, M, assign: the partition tests' graphs
using model::testing::link_model;

// t0 -> t1 -> t2 through data x and y (costs 3, 4, 5).
StepGraph chain() {
  Builder b;
  const DatumId x = b.datum("x", 100), y = b.datum("y", 100);
  b.task({{x, M::W}}, 3);
  b.task({{x, M::R}, {y, M::W}}, 4);
  b.task({{y, M::R}}, 5);
  return b.done();
}

TEST(Simulator, RunsAChainOnOneProcessorBackToBack) {
  const Schedule s = simulate(chain(), assign(1, {0, 0, 0}), link_model(10, 1));
  EXPECT_EQ(s.makespan_ns, 12u);
  EXPECT_EQ(s.signals, 0u);
  EXPECT_EQ(s.waits, 0u);
  EXPECT_EQ(s.end_ns, (std::vector<std::uint64_t>{3, 7, 12}));
}

TEST(Simulator, ChargesTheRuntimesOverheadOncePerTaskInstance) {
  CostModel m = link_model(10, 0);
  m.task_overhead_ns = 2;
  // One processor: 3 + 2, 4 + 2, 5 + 2 back to back.
  EXPECT_EQ(simulate(chain(), assign(1, {0, 0, 0}), m).end_ns,
            (std::vector<std::uint64_t>{5, 11, 18}));
  // Two: p0 t0 [0,5]; p1 t1 waits 5 + 10 -> [15,21]; p0 t2 waits 21 + 10 -> [31,38].
  const Schedule s = simulate(chain(), assign(2, {0, 1, 0}), m);
  EXPECT_EQ(s.start_ns, (std::vector<std::uint64_t>{0, 15, 31}));
  EXPECT_EQ(s.makespan_ns, 38u);
  EXPECT_EQ(s.busy_ns, (std::vector<std::uint64_t>{12, 6}));
}

TEST(Simulator, ChargesLatencyForEachCrossProcessorWait) {
  // p0: t0 [0,3]; p1: t1 waits 3 + 10 -> [13,17]; p0: t2 waits 17 + 10 -> [27,32].
  const Schedule s = simulate(chain(), assign(2, {0, 1, 0}), link_model(10, 0));
  EXPECT_EQ(s.start_ns, (std::vector<std::uint64_t>{0, 13, 27}));
  EXPECT_EQ(s.makespan_ns, 32u);
  EXPECT_EQ(s.signals, 2u);
  EXPECT_EQ(s.waits, 2u);
  EXPECT_EQ(s.busy_ns, (std::vector<std::uint64_t>{8, 4}));
}

TEST(Simulator, ChargesTransferBytesOncePerVersionAndProcessor) {
  Builder b;
  const DatumId x = b.datum("x", 100);
  b.task({{x, M::W}}, 3);  // p0
  b.task({{x, M::R}}, 4);  // p1: waits 3 + 1, pays 100 x 0.5 = 50 -> [4, 58]
  b.task({{x, M::R}}, 4);  // p1: same version already here -> [58, 62]
  const Schedule s = simulate(b.done(), assign(2, {0, 1, 1}), link_model(1, 0.5));
  EXPECT_EQ(s.start_ns, (std::vector<std::uint64_t>{0, 4, 58}));
  EXPECT_EQ(s.makespan_ns, 62u);
  EXPECT_EQ(s.transfer_bytes, 100u);
  EXPECT_EQ(s.waits, 1u);
  EXPECT_EQ(s.signals, 1u);
}

TEST(Simulator, ReadersOfOneFanInShareItsArrivalButNotItsCharges) {
  // 16 CW writers of d (cost 100, alternating p0 / p1) and four readers (cost 10, two on
  // each processor): every processor's writers end at 800, the other's arrive at 800 + 10.
  // The first reader on a processor waits for the 8 remote writers (8 waits, 8 x 64 bytes
  // at 0.5 ns); the second one only for the first.
  Builder b;
  const DatumId d = b.datum("d", 64);
  std::vector<ProcId> proc;
  for (int j = 0; j < 16; ++j) {
    b.task({{d, M::CW}}, 100);
    proc.push_back(static_cast<ProcId>(j % 2));
  }
  for (int j = 0; j < 4; ++j) {
    b.task({{d, M::R}}, 10);
    proc.push_back(static_cast<ProcId>(j % 2));
  }
  const Schedule s = simulate(b.done(), assign(2, proc), link_model(10, 0.5));
  // 810 + 8 x 64 x 0.5 = 256 -> [810, 1076]; then [1076, 1086].
  EXPECT_EQ(s.start_ns[16], 810u);
  EXPECT_EQ(s.start_ns[18], 1076u);
  EXPECT_EQ(s.start_ns[17], 810u);
  EXPECT_EQ(s.start_ns[19], 1076u);
  EXPECT_EQ(s.makespan_ns, 1086u);
  EXPECT_EQ(s.waits, 16u);
  EXPECT_EQ(s.signals, 16u);
  EXPECT_EQ(s.transfer_bytes, 16u * 64u);
}

TEST(Simulator, RunsForkJoinInParallel) {
  Builder b;
  const DatumId s0 = b.datum("s", 8), u = b.datum("u", 8), v = b.datum("v", 8);
  b.task({{s0, M::W}}, 2);             // 0 on p0
  b.task({{s0, M::R}, {u, M::W}}, 5);  // 1 on p0
  b.task({{s0, M::R}, {v, M::W}}, 7);  // 2 on p1
  b.task({{u, M::R}, {v, M::R}}, 1);   // 3 on p0
  const StepGraph g = b.done();
  EXPECT_EQ(simulate(g, assign(2, {0, 0, 1, 0}), CostModel::ideal()).makespan_ns, 10u);
  // With latency 3: task 2 starts at 5, ends 12; task 3 starts 15, ends 16.
  const Schedule s = simulate(g, assign(2, {0, 0, 1, 0}), link_model(3, 0));
  EXPECT_EQ(s.start_ns[2], 5u);
  EXPECT_EQ(s.start_ns[3], 15u);
  EXPECT_EQ(s.makespan_ns, 16u);
}

// Loop body: A (cost 2) writes x; B, the break (cost 3), reads x and the condition.
StepGraph loop3() {
  Builder b;
  const DatumId x = b.datum("x", 8), c = b.datum("cond", 1);
  b.task({{x, M::W}}, 2);
  b.task({{x, M::R}, {c, M::RW}}, 3);
  b.loop(c, 0, 2, 3);
  return b.done();
}

TEST(Simulator, RunsEveryLoopIterationAfterThePreviousBreak) {
  const StepGraph g = loop3();
  const Schedule one = simulate(g, assign(1, {0, 0}), link_model(1, 0));
  EXPECT_EQ(one.makespan_ns, 15u);
  EXPECT_EQ(one.first_instance, (std::vector<std::uint64_t>{0, 3, 6}));
  EXPECT_EQ(compute_metrics(g).span_ns, 15u);
  EXPECT_EQ(simulate(g, assign(2, {0, 1}), CostModel::ideal()).makespan_ns, 15u);
}

TEST(Simulator, ReplicatesLoopControlOnEveryProcessorOfTheBody) {
  // A on p0, B (the break) on p1, latency 1:
  //   it 0: A [0,2]   B [3,6]
  //   it 1: A waits break 6 + 1 -> [7,9]    B waits A 9 + 1 -> [10,13]
  //   it 2: A [14,16]  B [17,20]; p0 learns the loop ended at 21.
  const Schedule s = simulate(loop3(), assign(2, {0, 1}), link_model(1, 0));
  EXPECT_EQ(s.start_ns, (std::vector<std::uint64_t>{0, 7, 14, 3, 10, 17}));
  EXPECT_EQ(s.finish_ns, (std::vector<std::uint64_t>{21, 20}));
  EXPECT_EQ(s.makespan_ns, 21u);
  // Per iteration: x to p1 and the loop decision to p0; between iterations also "B has
  // read x" to p0 before A overwrites it (loop-carried WAR): 3 + 3 + 2.
  EXPECT_EQ(s.waits, 8u);
}

TEST(Simulator, FollowsTheGivenOrderAndDetectsDeadlocks) {
  Builder b;
  const DatumId x = b.datum("x", 8), y = b.datum("y", 8);
  b.task({{x, M::W}}, 5);
  b.task({{y, M::W}}, 2);
  const StepGraph g = b.done();
  Assignment a = assign(1, {0, 0});
  a.order = {{1, 0}};
  const Schedule s = simulate(g, a, CostModel::ideal());
  EXPECT_EQ(s.start_ns, (std::vector<std::uint64_t>{2, 0}));

  const StepGraph c = chain();
  Assignment bad = assign(1, {0, 0, 0});
  bad.order = {{2, 1, 0}};
  EXPECT_THROW(simulate(c, bad, CostModel::ideal()), Error);
  Assignment missing = assign(1, {0, 0, 0});
  missing.order = {{0, 1}};
  EXPECT_THROW(simulate(c, missing, CostModel::ideal()), Error);
  EXPECT_THROW(simulate(c, assign(2, {0, 2, 0}), CostModel::ideal()), Error);
  EXPECT_THROW(simulate(c, assign(2, {0, 1}), CostModel::ideal()), Error);
}

TEST(Simulator, IdealModelNeverBeatsTheLowerBoundOnRandomGraphs) {
  const std::vector<std::string> methods = {"random", "roundrobin", "owner", "metis", "list"};
  int checked = 0;
  for (std::uint64_t seed = 1; seed <= 150; ++seed) {
    const StepGraph g = partition::testing::random_graph(
        seed, 10 + static_cast<int>(seed % 50), 2 + static_cast<int>(seed % 9), seed % 3 != 0);
    const Metrics m = compute_metrics(g);
    for (std::uint32_t k : {1u, 2u, 3u, 5u, 8u}) {
      const std::uint64_t bound = std::max<std::uint64_t>((m.work_ns + k - 1) / k, m.span_ns);
      for (const std::string& method : methods) {
        const Result r = make_strategy(method)->partition(g, k, {}, {});
        const Schedule ideal = simulate(g, r.assignment, CostModel::ideal());
        ASSERT_GE(ideal.makespan_ns, bound) << method << " k=" << k << " seed=" << seed;
        const Schedule costly = simulate(g, r.assignment, link_model(50, 0.1));
        ASSERT_GE(costly.makespan_ns, ideal.makespan_ns)
            << method << " k=" << k << " seed=" << seed;
        if (k == 1) {
          ASSERT_EQ(ideal.makespan_ns, m.work_ns);
        }
        ++checked;
      }
    }
  }
  EXPECT_EQ(checked, 150 * 5 * 5);
}

}  // namespace
}  // namespace tgraph::model
