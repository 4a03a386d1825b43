// SPDX-License-Identifier: MIT
// Partition-guided stealing (PartitionOptions::steal): which tasks a thief may take and what
// it must wait for (partition_plan.hpp add_steal()), and threads with nothing mapped taking
// the ready tasks of a loaded processor with the results unchanged.
#include <gtest/gtest.h>

#include <algorithm>
#include <string>
#include <vector>

#include "partition_plan.hpp"
#include "random_graph.hpp"
#include "tgraph/graph/lowering.hpp"
#include "tgraph/replay/executor.hpp"
#include "tgraph/replay/synthetic.hpp"

namespace tgraph::replay {
namespace {

using detail::PartitionPlan;
using detail::WaitKind;
using detail::WaitPoint;

using test::chain_graph;

std::vector<WaitPoint> steal_waits_of(const PartitionPlan& plan, TaskId t) {
  return {plan.steal_waits.begin() + plan.steal_begin[t],
          plan.steal_waits.begin() + plan.steal_begin[t + 1]};
}

bool has(const std::vector<WaitPoint>& ws, TaskId producer, WaitKind kind) {
  return std::any_of(ws.begin(), ws.end(), [&](const WaitPoint& w) {
    return w.producer == producer && w.kind == kind;
  });
}

TEST(PartitionSteal, ATaskWaitsForEveryPredecessorAndTheLastCumulativeWriterBeforeItOnItsProcessor) {
  // t0, t1, t2 add into d0 on processor 0 (no edges between them), t3 reads d0 on
  // processor 1; t4 writes d1 on processor 0.
  const StepGraph g = chain_graph({{{0, AccessMode::CW}},
                                   {{0, AccessMode::CW}},
                                   {{0, AccessMode::CW}},
                                   {{0, AccessMode::R}},
                                   {{1, AccessMode::W}}},
                                  2);
  Assignment a;
  a.k = 2;
  a.proc = {0, 0, 0, 1, 0};
  const ExecGraph x = lower(g, &a, CwMode::kReduce);
  PartitionPlan plan = detail::build_plan(x, 2, true, true);
  detail::add_steal(x, plan);
  ASSERT_EQ(plan.stealable.size(), x.graph.tasks.size());
  EXPECT_TRUE(steal_waits_of(plan, 0).empty());
  EXPECT_EQ(steal_waits_of(plan, 1), (std::vector<WaitPoint>{{0, kNoLoop, WaitKind::kOnce}}));
  // Only the writer just before it: the chain orders the others.
  EXPECT_EQ(steal_waits_of(plan, 2), (std::vector<WaitPoint>{{1, kNoLoop, WaitKind::kOnce}}));
  // A reader waits for every writer, on its own processor or not.
  const std::vector<WaitPoint> reader = steal_waits_of(plan, 3);
  for (TaskId w : {0u, 1u, 2u}) EXPECT_TRUE(has(reader, w, WaitKind::kOnce)) << w;
  EXPECT_TRUE(steal_waits_of(plan, 4).empty());
  for (TaskId t = 0; t < x.graph.tasks.size(); ++t) EXPECT_EQ(plan.stealable[t], 1) << t;
}

TEST(PartitionSteal, BreaksAndCombinedReductionsStayWithTheirProcessorsAndLoopWaitsKeepTheirKind) {
  const test::DotLoop d = test::dot_loop(6, 3, 4, 0, 0);
  const ExecGraph x = lower(d.g, &d.a, CwMode::kReduce);
  PartitionPlan plan = detail::build_plan(x, 3, true, true);
  detail::add_combines(x, plan);
  detail::add_steal(x, plan);
  ASSERT_FALSE(plan.combines.empty());
  std::vector<bool> in_combine(plan.tasks, false);
  for (const detail::Combine& c : plan.combines)
    for (std::uint32_t i = c.head; i < c.end; ++i)
      in_combine[plan.procs[c.home].ops[i].task] = true;
  std::size_t stealable = 0;
  for (const auto& pp : plan.procs)
    for (const detail::Op& op : pp.ops) {
      if (op.kind != detail::OpKind::kTask) continue;
      const bool excluded = op.is_break || op.combine != detail::CombineRole::kNone || in_combine[op.task];
      EXPECT_EQ(plan.stealable[op.task] != 0, !excluded) << x.graph.kind_name(op.task);
      stealable += plan.stealable[op.task];
      if (!plan.stealable[op.task]) {
        EXPECT_EQ(plan.steal_begin[op.task], plan.steal_begin[op.task + 1]);
      }
    }
  EXPECT_GT(stealable, 0u);
  // An update task reads the scalar of the same iteration and rewrites its vector, which
  // the partial of the next iteration reads: kSameIter and kPrevIter waits.
  for (TaskId t = 0; t < plan.tasks; ++t) {
    if (x.graph.kind_name(t) == "update" && plan.stealable[t]) {
      const auto ws = steal_waits_of(plan, t);
      EXPECT_TRUE(std::any_of(ws.begin(), ws.end(),
                              [](const WaitPoint& w) { return w.kind == WaitKind::kSameIter; }));
    }
    if (x.graph.kind_name(t) == "partial" && plan.stealable[t]) {
      const auto ws = steal_waits_of(plan, t);
      EXPECT_TRUE(std::any_of(ws.begin(), ws.end(),
                              [](const WaitPoint& w) { return w.kind == WaitKind::kPrevIter; }));
    }
  }
}

// Every task of a random program on processor 0 of k: the other threads have nothing
// mapped and take ready tasks of processor 0 (they spin for as long as the step lasts).
TEST(PartitionSteal, ThreadsWithNothingMappedTakeReadyTasksOfTheLoadedProcessorAndTheStateIsKept) {
  constexpr std::uint32_t k = 3;
  std::uint64_t stolen = 0, off = 0;
  for (std::uint32_t seed = 1; seed <= 4; ++seed) {
    const StepGraph g = test::random_graph(seed * 31 + 5, 6, 14);
    Assignment a;
    a.k = k;
    a.proc.assign(g.tasks.size(), 0);
    ExecOptions o = test::partition_options(k, false, 2'000'000'000);
    auto ex = make_executor(Policy::kPartition, o);
    TimelineObserver timeline;
    ex->add_observer(timeline);
    SyntheticWorkload w({.cost_scale = 5.0});
    w.set_step(g);
    for (std::uint32_t step = 0; step < 2; ++step) {
      const ExecStepStats s = ex->run_step(g, &a, w);
      test::expect_valid_order(ex->last_exec()->graph, timeline.timeline().tasks, step,
                               {.exec = true});
      std::uint64_t run = 0;
      for (std::uint32_t p = 0; p < k; ++p) {
        run += s.threads[p].tasks;
        if (p > 0) {
          EXPECT_EQ(s.threads[p].stolen, s.threads[p].tasks);  // nothing of its own
        }
        stolen += s.threads[p].stolen;
      }
      EXPECT_EQ(s.threads[0].stolen, 0u);
      std::uint64_t instances = 0;
      for (const TimelineTask& e : timeline.timeline().tasks)
        if (e.step == step) {
          ++instances;
          if (e.thread != 0) ++off;
        }
      EXPECT_EQ(run, instances);
    }
    const auto got = test::final_state(w, g), want = test::sequential_state(g, 2);
    for (DatumId d = 0; d < g.data.size(); ++d)
      EXPECT_TRUE(got[d] == want[d]) << "seed " << seed << ": datum " << g.data[d].name;
  }
  EXPECT_GT(stolen, 0u);
  EXPECT_EQ(off, stolen);  // what ran off processor 0 is what the counters call stolen
}

TEST(PartitionSteal, WithoutStealingEveryTaskRunsOnItsProcessor) {
  const StepGraph g = test::random_graph(77, 4, 10);
  const Assignment a = test::random_assignment(g, 3, 5);
  ExecOptions o = test::partition_options(3, false, 20'000);
  o.partition.steal = false;
  o.partition.combine = false;
  auto ex = make_executor(Policy::kPartition, o);
  TimelineObserver timeline;
  ex->add_observer(timeline);
  SyntheticWorkload w({.cost_scale = 0.2});
  w.set_step(g);
  const ExecStepStats s = ex->run_step(g, &a, w);
  const ExecGraph& x = *ex->last_exec();
  ASSERT_FALSE(timeline.timeline().tasks.empty());
  for (const TimelineTask& e : timeline.timeline().tasks)
    EXPECT_EQ(e.thread, x.assignment.proc[e.task]) << x.graph.kind_name(e.task);
  EXPECT_EQ(s.threads[0].stolen + s.threads[1].stolen + s.threads[2].stolen, 0u);
}

}  // namespace
}  // namespace tgraph::replay
