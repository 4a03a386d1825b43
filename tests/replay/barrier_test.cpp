// SPDX-License-Identifier: MIT
// The barrier policy's phases: an omp for per operation with nowait where it is safe
// (default), one per dependency level, or one per operation with a barrier after each.
#include <gtest/gtest.h>

#include "random_graph.hpp"
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

/// One step of `g` under the barrier policy at 2 threads with `rule`, bodies `w`.
ExecStepStats run_barrier(const StepGraph& g, BarrierRule rule, SyntheticWorkload& w) {
  ExecOptions o;
  o.threads = 2;
  o.pin = false;
  o.barrier.rule = rule;
  auto ex = make_executor(Policy::kBarrier, o);
  w.set_step(g);
  return ex->run_step(g, nullptr, w);
}

/// Barriers each thread passed in one step of `g` (one per phase run).
std::uint64_t phases(const StepGraph& g, BarrierRule rule) {
  SyntheticWorkload w({.cost_scale = 0.0});
  const ExecStepStats s = run_barrier(g, rule, w);
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

/// A CG-like sequence over `n` objects: axpy_i (RW x_i), scale_i (RW x_i), dot_i (R x_i, CW
/// s), then use_i (R s, RW y_i): each operation reads only its own object's results of the
/// one before, but for the dot product's sum.
StepGraph cg_like(int n) {
  StepGraph g;
  const KindId axpy = g.intern_kind("axpy"), scale = g.intern_kind("scale"),
               dot = g.intern_kind("dot"), use = g.intern_kind("use");
  for (int i = 0; i < n; ++i) g.objects.push_back({"o" + std::to_string(i)});
  for (int i = 0; i < n; ++i) g.data.push_back({"x" + std::to_string(i), static_cast<ObjectId>(i), 64});
  for (int i = 0; i < n; ++i) g.data.push_back({"y" + std::to_string(i), static_cast<ObjectId>(i), 64});
  const auto s = static_cast<DatumId>(g.data.size());
  g.data.push_back({"s", kNoObject, 8});
  StableKey key = 1;
  const auto x = [](int i) { return static_cast<DatumId>(i); };
  for (int i = 0; i < n; ++i)
    g.add_task(axpy, static_cast<ObjectId>(i), std::vector<Access>{{x(i), AccessMode::RW}}, 0, key++);
  for (int i = 0; i < n; ++i)
    g.add_task(scale, static_cast<ObjectId>(i), std::vector<Access>{{x(i), AccessMode::RW}}, 0, key++);
  for (int i = 0; i < n; ++i)
    g.add_task(dot, static_cast<ObjectId>(i),
               std::vector<Access>{{x(i), AccessMode::R}, {s, AccessMode::CW}}, 0, key++);
  for (int i = 0; i < n; ++i)
    g.add_task(use, static_cast<ObjectId>(i),
               std::vector<Access>{{s, AccessMode::R}, {static_cast<DatumId>(n + i), AccessMode::RW}},
               0, key++);
  g.derive_edges();
  return g;
}

TEST(BarrierRule, OmpForDropsTheBarriersBetweenOperationsOnTheSameObjects) {
  const StepGraph g = cg_like(4);
  // axpy, scale and dot on each thread's own objects without a barrier; one before the
  // reducer (every thread's writers) and one before use (it reads the sum); one at the end.
  EXPECT_EQ(phases(g, BarrierRule::kOmpFor), 3u);
  EXPECT_EQ(phases(g, BarrierRule::kOperation), 5u);  // axpy | scale | dot | reduce | use
  EXPECT_EQ(phases(g, BarrierRule::kLevel), 5u);
  // The sums are the sequential run's under every rule.
  for (BarrierRule rule : {BarrierRule::kOmpFor, BarrierRule::kLevel, BarrierRule::kOperation}) {
    SyntheticWorkload w({.cost_scale = 0.0});
    run_barrier(g, rule, w);
    EXPECT_EQ(test::final_state(w, g), test::sequential_state(g, 1)) << to_string(rule);
  }
}

TEST(BarrierRule, OmpForKeepsABarrierWhereAnOperationReadsAnotherThreadsObject) {
  // Interleaved chains put each task alone in its phase, on thread 0: no barrier but the last.
  EXPECT_EQ(phases(interleaved_chains(5), BarrierRule::kOmpFor), 1u);
  // Shifted reads: b_i reads x_(i+1), written by a_(i+1), on the other thread for i = 1.
  StepGraph g;
  const KindId a = g.intern_kind("a"), b = g.intern_kind("b");
  for (int i = 0; i < 4; ++i) {
    g.objects.push_back({"o" + std::to_string(i)});
    g.data.push_back({"x" + std::to_string(i), static_cast<ObjectId>(i), 64});
  }
  for (int i = 0; i < 4; ++i) g.data.push_back({"y" + std::to_string(i), static_cast<ObjectId>(i), 64});
  for (int i = 0; i < 4; ++i)
    g.add_task(a, static_cast<ObjectId>(i),
               std::vector<Access>{{static_cast<DatumId>(i), AccessMode::W}}, 0,
               static_cast<StableKey>(i + 1));
  for (int i = 0; i < 4; ++i)
    g.add_task(b, static_cast<ObjectId>(i),
               std::vector<Access>{{static_cast<DatumId>((i + 1) % 4), AccessMode::R},
                                   {static_cast<DatumId>(4 + i), AccessMode::W}},
               0, static_cast<StableKey>(i + 5));
  g.derive_edges();
  EXPECT_EQ(phases(g, BarrierRule::kOmpFor), 2u);
}

TEST(BarrierRule, NamesAndParsing) {
  EXPECT_EQ(to_string(BarrierRule::kLevel), "level");
  EXPECT_EQ(to_string(BarrierRule::kOperation), "operation");
  EXPECT_EQ(to_string(BarrierRule::kOmpFor), "omp-for");
  EXPECT_EQ(parse_barrier_rule("operation"), BarrierRule::kOperation);
  EXPECT_EQ(parse_barrier_rule("omp-for"), BarrierRule::kOmpFor);
  EXPECT_EQ(ExecOptions{}.barrier.rule, BarrierRule::kOmpFor);  // the default
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
