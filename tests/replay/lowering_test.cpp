// SPDX-License-Identifier: MIT
#include "tgraph/graph/lowering.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <string>
#include <utility>
#include <vector>

#include "random_graph.hpp"
#include "tgraph/graph/error.hpp"
#include "tgraph/replay/executor.hpp"
#include "tgraph/replay/synthetic.hpp"
#if defined(TGRAPH_HAVE_PARTITION)
#include "tgraph/partition/strategy.hpp"
#endif

namespace tgraph::replay {
namespace {

/// Two CW groups whose reducers land on different processors, each fed only by the other
/// processor (the shape of bars64's force accumulation under `list`):
///   t0 W a (p0)   t1 W b (p1)          resets
///   t2 CW a (p1)  t3 CW b (p0)         first writers: the homes (a: p1, b: p0)
///   t4 CW a (p0)  t5 CW b (p1)         off-home writers -> temporaries a@0, b@1
///   t6 R a (p1)   t7 R b (p0)          readers
/// The reducer of a (home p1) depends, through the graph's edges, only on t0 and t4 (p0),
/// the reducer of b (home p0) only on t1 and t5 (p1). Placed by edges alone, both went to
/// the front of their processor's order and waited for each other's processor: a deadlock.
/// With `in_loop`, the same tasks form a loop body, with a residual and a break on p0.
// Appends a task of object 0 (cost 1000, key = its id + 1), in loop 0 when `in_loop`.
void add_task(StepGraph& g, KindId kind, std::vector<Access> acc, bool in_loop) {
  const auto t = static_cast<TaskId>(g.tasks.size());
  g.add_task(kind, 0, acc, 1000, static_cast<StableKey>(t + 1));
  if (in_loop) g.tasks[t].loop = 0;
}

StepGraph crossing_reducers(bool in_loop) {
  StepGraph g;
  g.intern_kind("reset");
  g.intern_kind("add");
  g.intern_kind("read");
  g.intern_kind("loop.break");
  g.objects.push_back({"o"});
  g.data = {{"a", 0, 64}, {"b", 0, 64}, {"cond", kNoObject, 8}};
  auto add = [&](KindId kind, std::vector<Access> acc) {
    add_task(g, kind, std::move(acc), in_loop);
  };
  add(0, {{0, AccessMode::W}});
  add(0, {{1, AccessMode::W}});
  add(1, {{0, AccessMode::CW}});
  add(1, {{1, AccessMode::CW}});
  add(1, {{0, AccessMode::CW}});
  add(1, {{1, AccessMode::CW}});
  add(2, {{0, AccessMode::R}});
  add(2, {{1, AccessMode::R}});
  if (in_loop) {
    add(2, {{0, AccessMode::R}, {2, AccessMode::W}});
    add(3, {{2, AccessMode::R}});
    Loop l;
    l.condition = 2;
    l.first = 0;
    l.last = static_cast<TaskId>(g.tasks.size());
    l.iterations = 3;
    g.loops.push_back(l);
  }
  g.derive_edges();
  EXPECT_EQ(g.validate(), "");
  return g;
}

Assignment crossing_assignment(const StepGraph& g) {
  Assignment a;
  a.k = 2;
  a.proc = {0, 1, 1, 0, 0, 1, 1, 0};
  a.order = {{0, 3, 4, 7}, {1, 2, 5, 6}};
  if (g.tasks.size() > 8) {
    a.proc.insert(a.proc.end(), {0, 0});
    a.order[0].insert(a.order[0].end(), {8, 9});
  }
  return a;
}

std::size_t index_in(const std::vector<TaskId>& order, TaskId t) {
  return static_cast<std::size_t>(std::find(order.begin(), order.end(), t) - order.begin());
}

class CrossingReducers : public ::testing::TestWithParam<bool> {};

TEST_P(CrossingReducers, AreOrderedAfterTheirAncestorsThroughOtherProcessorsOrders) {
  const StepGraph g = crossing_reducers(GetParam());
  const Assignment a = crossing_assignment(g);
  const ExecGraph x = lower(g, &a, CwMode::kReduce);
  ASSERT_EQ(x.reductions.size(), 2u);
  // The reducers of a and b, each emitted right before its datum's reader.
  const TaskId ra = x.exec_of[6] - 1, rb = x.exec_of[7] - 1;
  ASSERT_EQ(x.reduction[ra], 0u);
  ASSERT_EQ(x.reduction[rb], 1u);
  EXPECT_EQ(x.assignment.proc[ra], 1u);
  EXPECT_EQ(x.assignment.proc[rb], 0u);
  const auto& o0 = x.assignment.order[0];
  const auto& o1 = x.assignment.order[1];
  ASSERT_EQ(o0.size() + o1.size(), x.graph.tasks.size());
  // a's reducer waits for t4 on p0, which follows t3, which waits for t1 on p1: it goes
  // right after t1 (not at the front of p1's order). b's reducer waits for t5 on p1, behind
  // t2 and a's reducer, which waits for t4: it goes right after t4 on p0.
  EXPECT_EQ(index_in(o1, ra), index_in(o1, x.exec_of[1]) + 1);
  EXPECT_EQ(index_in(o0, rb), index_in(o0, x.exec_of[4]) + 1);
}

TEST_P(CrossingReducers, RunWithTheExplicitOrderAndMatchTheSequentialState) {
  const StepGraph g = crossing_reducers(GetParam());
  const Assignment a = crossing_assignment(g);
  std::vector<std::vector<std::uint64_t>> want;
  {
    auto seq = make_executor(Policy::kSequential, {});
    SyntheticWorkload w({.cost_scale = 0.0});
    w.set_step(g);
    seq->run_step(g, nullptr, w);
    for (DatumId d = 0; d < g.data.size(); ++d) {
      auto words = w.words(d);
      want.emplace_back(words.begin(), words.end());
    }
  }
  for (bool serial : {true, false}) {
    auto ex = make_executor(Policy::kPartition, test::partition_options(2, serial, 20'000));
    SyntheticWorkload w({.cost_scale = 0.0});
    w.set_step(g);
    ASSERT_NO_THROW(ex->run_step(g, &a, w)) << (serial ? "serial" : "threads");
    EXPECT_EQ(ex->order_fallbacks(), 0u);
    for (DatumId d = 0; d < g.data.size(); ++d) {
      auto words = w.words(d);
      EXPECT_TRUE(std::vector<std::uint64_t>(words.begin(), words.end()) == want[d])
          << (serial ? "serial" : "threads") << ": datum " << g.data[d].name;
    }
  }
}

INSTANTIATE_TEST_SUITE_P(StraightAndLoop, CrossingReducers, ::testing::Bool(),
                         [](const auto& p) { return p.param ? "InLoop" : "Straight"; });

/// Two loops; processor 0 holds only loop A's break task and loop B's first CW writer of y
/// (the home of y's group), processor 1 everything else (the shape of falling under `list`):
///   loop A: a0 W x (p1), a1 R x W ca (p1), a2 break R ca (p0)
///   loop B: b0 CW y (p0), b1 CW y (p1) -> y@1, b2 R y W cb (p1), b3 break R cb (p1)
/// The reducer of y (loop B, home p0) waits for b1, which p1 runs after leaving loop A, that
/// is after p0's a2 decided A's exit. By edges alone it had no ancestor on p0 and went to
/// the front of p0's order, pulling p0's whole B block ahead of A: a deadlock.
// Two processors accumulate f; p0, the home, has an independent task (on g) between its
// write and f's reader in program order. The reducer is emitted right before the reader,
// so p0 runs the independent task first instead of blocking on p1's writer; in a loop the
// reducer stays in the loop.
TEST(CwReduction, TheReducerGoesRightBeforeItsReaderAfterTheHomesIndependentWork) {
  for (bool in_loop : {false, true}) {
    StepGraph g;
    g.intern_kind("add");
    g.intern_kind("other");
    g.intern_kind("read");
    g.intern_kind("loop.break");
    g.objects.push_back({"o"});
    g.data = {{"f", 0, 64}, {"g", 0, 64}, {"cond", kNoObject, 8}};
    auto add = [&](KindId kind, std::vector<Access> acc) {
    add_task(g, kind, std::move(acc), in_loop);
  };
    add(0, {{0, AccessMode::CW}});
    add(0, {{0, AccessMode::CW}});
    add(1, {{1, AccessMode::RW}});
    add(2, {{0, AccessMode::R}, {2, AccessMode::W}});
    if (in_loop) {
      add(3, {{2, AccessMode::R}});
      g.loops.push_back({2, 0, 5, 3, 0});
    }
    g.derive_edges();
    ASSERT_EQ(g.validate(), "");
    Assignment a;
    a.k = 2;
    a.proc = {0, 1, 0, 0};
    if (in_loop) a.proc.push_back(0);
    const ExecGraph x = lower(g, &a, CwMode::kReduce);
    ASSERT_EQ(x.reductions.size(), 1u);
    const TaskId r = x.exec_of[3] - 1;
    ASSERT_EQ(x.reduction[r], 0u) << in_loop;
    EXPECT_LT(x.exec_of[2], r);
    EXPECT_EQ(x.assignment.proc[r], 0u);
    EXPECT_EQ(x.graph.tasks[r].loop, in_loop ? 0u : kNoLoop);
    if (in_loop) {
      EXPECT_EQ(x.graph.loops[0].last, x.exec_of[4] + 1);
    }
    for (bool serial : {true, false}) {
      auto ex = make_executor(Policy::kPartition, test::partition_options(2, serial, 20'000));
      SyntheticWorkload w({.cost_scale = 0.0});
      w.set_step(g);
      ASSERT_NO_THROW(ex->run_step(g, &a, w)) << (serial ? "serial" : "threads");
    }
  }
}

TEST(CwReduction, ReducerStaysInItsLoopBlockBehindTheExitOfEarlierLoops) {
  StepGraph g;
  g.intern_kind("k");
  g.intern_kind("loop.break");
  g.objects.push_back({"o"});
  g.data = {{"x", 0, 64}, {"ca", kNoObject, 8}, {"y", 0, 64}, {"cb", kNoObject, 8}};
  auto add = [&](KindId kind, LoopId l, std::vector<Access> acc) {
    const auto t = static_cast<TaskId>(g.tasks.size());
    g.add_task(kind, 0, acc, 1000, static_cast<StableKey>(t + 1));
    g.tasks[t].loop = l;
  };
  add(0, 0, {{0, AccessMode::W}});
  add(0, 0, {{0, AccessMode::R}, {1, AccessMode::W}});
  add(1, 0, {{1, AccessMode::R}});
  add(0, 1, {{2, AccessMode::CW}});
  add(0, 1, {{2, AccessMode::CW}});
  add(0, 1, {{2, AccessMode::R}, {3, AccessMode::W}});
  add(1, 1, {{3, AccessMode::R}});
  g.loops.push_back({1, 0, 3, 2, 0});
  g.loops.push_back({3, 3, 7, 2, 0});
  g.derive_edges();
  ASSERT_EQ(g.validate(), "");
  Assignment a;
  a.k = 2;
  a.proc = {1, 1, 0, 0, 1, 1, 1};
  a.order = {{2, 3}, {0, 1, 4, 5, 6}};
  const ExecGraph x = lower(g, &a, CwMode::kReduce);
  ASSERT_EQ(x.reductions.size(), 1u);
  const TaskId r = x.exec_of[4] + 1;
  ASSERT_EQ(x.origin[r], kNoTask);
  EXPECT_EQ(x.assignment.order[0], (std::vector<TaskId>{x.exec_of[2], r, x.exec_of[3]}));
  for (bool serial : {true, false}) {
    auto ex = make_executor(Policy::kPartition, test::partition_options(2, serial, 20'000));
    SyntheticWorkload w({.cost_scale = 0.0});
    w.set_step(g);
    ExecStepStats s;
    ASSERT_NO_THROW(s = ex->run_step(g, &a, w)) << (serial ? "serial" : "threads");
    EXPECT_EQ(ex->order_fallbacks(), 0u);
    EXPECT_EQ(s.loop_iterations, (std::vector<std::uint32_t>{2, 2}));
  }
}

#if defined(TGRAPH_HAVE_PARTITION)
// The `list` strategy's orders (loops as blocks) on random programs with CW groups and
// loops: lowering's reducers must keep them runnable, without the program-order fallback.
TEST(CwReduction, ListScheduleOrdersRunWithReducersOnRandomPrograms) {
  auto list = partition::make_strategy("list");
  std::size_t reducers = 0, in_loops = 0;
  for (std::uint32_t seed = 1; seed <= 150; ++seed) {
    const StepGraph g = test::random_graph(seed, 1 + static_cast<int>(seed % 4), 12, 10);
    for (std::uint32_t k : {2u, 3u, 4u}) {
      const Assignment a = list->partition(g, k, {}, partition::Options{}).assignment;
      ASSERT_FALSE(a.order.empty());
      auto ex = make_executor(Policy::kPartition, test::partition_options(k, true));
      SyntheticWorkload w({.cost_scale = 0.0});
      w.set_step(g);
      ASSERT_NO_THROW(ex->run_step(g, &a, w)) << "seed " << seed << " k " << k;
      const ExecGraph& x = *ex->last_exec();
      // Serialised CW writers (added edges) may legitimately need program order; reducers
      // alone never may.
      if (x.added_edges) continue;
      EXPECT_EQ(ex->order_fallbacks(), 0u) << "seed " << seed << " k " << k;
      reducers += x.reductions.size();
      for (TaskId t = 0; t < x.graph.tasks.size(); ++t)
        if (x.origin[t] == kNoTask && x.graph.tasks[t].loop != kNoLoop) ++in_loops;
    }
  }
  // The programs do exercise the reducer placement, in loops too (141 and 23 reducers).
  EXPECT_GT(reducers, 100u);
  EXPECT_GT(in_loops, 10u);
}

// Programs of every shape (segments, loop sizes, data) under `list` and `metis` orders on
// 2..6 processors run without deadlock. Found by this test: a reducer placed before its
// home processor's block of a loop whose exit it waits for (seed 10, k 4), and serialised CW
// writers across a loop boundary whose added edge needs a task that `list` put after
// another processor's block of the loop, which deadlocked from the third iteration on while
// the plan's two-iteration check passed (seed 1369, k 4; now the explicit order is dropped).
TEST(CwReduction, OrdersRunWithoutDeadlockOnRandomProgramsOfEveryShape) {
  std::uint64_t fallbacks = 0;
  for (const char* name : {"list", "metis"}) {
    auto strategy = partition::make_strategy(name);
    for (std::uint32_t seed = 1; seed <= 800; ++seed) {
      const StepGraph g = test::random_graph(seed, 1 + static_cast<int>(seed % 5),
                                             6 + static_cast<int>(seed % 9),
                                             4 + static_cast<int>(seed % 8));
      for (std::uint32_t k : {2u, 3u, 4u, 6u}) {
        const Assignment a = strategy->partition(g, k, {}, partition::Options{}).assignment;
        auto ex = make_executor(Policy::kPartition, test::partition_options(k, true));
        SyntheticWorkload w({.cost_scale = 0.0});
        w.set_step(g);
        ASSERT_NO_THROW(ex->run_step(g, &a, w)) << name << " seed " << seed << " k " << k;
        if (!ex->last_exec()->added_edges) {
          EXPECT_EQ(ex->order_fallbacks(), 0u) << name << " seed " << seed << " k " << k;
        }
        fallbacks += ex->order_fallbacks();
      }
    }
  }
  EXPECT_GT(fallbacks, 0u);  // the serialised case above does occur
}

TEST(CwReduction, AnOrderThatNeedsATaskBehindAnotherProcessorsLoopBlockFallsBack) {
  const StepGraph g = test::random_graph(1369, 5, 7, 5);
  const Assignment a =
      partition::make_strategy("list")->partition(g, 4, {}, partition::Options{}).assignment;
  ASSERT_FALSE(a.order.empty());
  auto ex = make_executor(Policy::kPartition, test::partition_options(4, true));
  SyntheticWorkload w({.cost_scale = 0.0});
  w.set_step(g);
  ASSERT_NO_THROW(ex->run_step(g, &a, w));
  EXPECT_TRUE(ex->last_exec()->added_edges);
  EXPECT_EQ(ex->order_fallbacks(), 1u);
}
#endif

}  // namespace
}  // namespace tgraph::replay
