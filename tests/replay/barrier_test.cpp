// SPDX-License-Identifier: MIT
// The barrier policy's phases: one per dependency level (default) or one per operation.
#include <gtest/gtest.h>

#include "tgraph/graph/error.hpp"
#include "tgraph/replay/executor.hpp"
#include "tgraph/replay/synthetic.hpp"

namespace tgraph::replay {
namespace {

/// Two independent chains of `length` tasks whose program order interleaves their kinds:
/// a0 b0 a1 b1 ... where a(i+1) reads and writes what a(i) wrote (RW on xa), b likewise on xb.
StepGraph interleaved_chains(int length) {
  StepGraph g;
  const KindId a = g.intern_kind("a"), b = g.intern_kind("b");
  g.objects = {{"A"}, {"B"}};
  g.data = {{"xa", 0, 64}, {"xb", 1, 64}};
  for (int i = 0; i < length; ++i) {
    g.add_task(a, 0, std::vector<Access>{{0, AccessMode::RW}}, 0, static_cast<StableKey>(2 * i + 1));
    g.add_task(b, 1, std::vector<Access>{{1, AccessMode::RW}}, 0, static_cast<StableKey>(2 * i + 2));
  }
  g.derive_edges();
  return g;
}

/// `n` independent tasks whose kinds alternate p, q, p, q... (each writes its own datum).
StepGraph alternating_kinds(int n) {
  StepGraph g;
  const KindId p = g.intern_kind("p"), q = g.intern_kind("q");
  for (int i = 0; i < n; ++i) {
    g.objects.push_back({"o" + std::to_string(i)});
    g.data.push_back({"d" + std::to_string(i), static_cast<ObjectId>(i), 64});
    g.add_task(i % 2 == 0 ? p : q, static_cast<ObjectId>(i),
               std::vector<Access>{{static_cast<DatumId>(i), AccessMode::W}}, 0,
               static_cast<StableKey>(i + 1));
  }
  g.derive_edges();
  return g;
}

/// Barriers each thread passed in one step of `g` (one per phase run).
std::uint64_t phases(const StepGraph& g, BarrierRule rule) {
  ExecOptions o;
  o.threads = 2;
  o.pin = false;
  o.barrier.rule = rule;
  auto ex = make_executor(Policy::kBarrier, o);
  SyntheticWorkload w({.cost_scale = 0.0});
  w.set_step(g);
  const ExecStepStats s = ex->run_step(g, nullptr, w);
  EXPECT_EQ(s.threads.size(), 2u);
  EXPECT_EQ(s.threads[0].waits, s.threads[1].waits);
  return s.threads[0].waits;
}

TEST(BarrierRule, IndependentKindsInterleavedInProgramOrderShareOnePhaseByLevel) {
  const StepGraph g = alternating_kinds(8);
  EXPECT_EQ(phases(g, BarrierRule::kLevel), 1u);
  EXPECT_EQ(phases(g, BarrierRule::kOperation), 8u);  // one per run of one kind
}

TEST(BarrierRule, TwoInterleavedChainsTakeOnePhasePerLevelNotPerTask) {
  const StepGraph g = interleaved_chains(5);
  EXPECT_EQ(phases(g, BarrierRule::kLevel), 5u);       // a(i) and b(i) together
  EXPECT_EQ(phases(g, BarrierRule::kOperation), 10u);  // a0 | b0 | a1 | b1 ...
}

TEST(BarrierRule, NamesAndParsing) {
  EXPECT_EQ(to_string(BarrierRule::kLevel), "level");
  EXPECT_EQ(to_string(BarrierRule::kOperation), "operation");
  EXPECT_EQ(parse_barrier_rule("operation"), BarrierRule::kOperation);
  EXPECT_FALSE(parse_barrier_rule("task").has_value());  // the flag's error: tests/apps
}

// A loop body of two independent chains: each iteration runs the body's levels, then the
// break's decision; iterations come from the workload as in every policy.
TEST(BarrierRule, LoopBodiesRunOnePhasePerLevelPerIteration) {
  StepGraph g;
  const KindId a = g.intern_kind("a"), b = g.intern_kind("b"), brk = g.intern_kind("loop.break");
  g.objects = {{"A"}, {"B"}};
  g.data = {{"xa", 0, 64}, {"xb", 1, 64}, {"cond", kNoObject, 8}};
  Loop loop;
  loop.condition = 2;
  loop.first = 0;
  loop.iterations = 3;
  for (int i = 0; i < 2; ++i) {
    g.tasks[g.add_task(a, 0, std::vector<Access>{{0, AccessMode::RW}}, 0, 10 + 2 * i)].loop = 0;
    g.tasks[g.add_task(b, 1, std::vector<Access>{{1, AccessMode::RW}}, 0, 11 + 2 * i)].loop = 0;
  }
  g.tasks[g.add_task(a, 0, std::vector<Access>{{0, AccessMode::R}, {2, AccessMode::W}}, 0, 20)]
      .loop = 0;
  g.tasks[g.add_task(brk, kNoObject, std::vector<Access>{{2, AccessMode::R}}, 0, 21)].loop = 0;
  loop.last = static_cast<TaskId>(g.tasks.size());
  g.loops.push_back(loop);
  g.derive_edges();
  ASSERT_EQ(g.validate(), "");
  // Levels: {a0, b0}, {a1, b1}, {residual}, {break} (it reads what the residual wrote):
  // 4 phases x 3 iterations.
  EXPECT_EQ(phases(g, BarrierRule::kLevel), 12u);
  // By operation: a0 | b0 | a1 | b1 | residual (a) | break: 6 phases x 3.
  EXPECT_EQ(phases(g, BarrierRule::kOperation), 18u);
}

}  // namespace
}  // namespace tgraph::replay
