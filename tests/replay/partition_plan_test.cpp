// SPDX-License-Identifier: MIT
// The partition executor's plans, built directly (replay/src/partition_plan.hpp): each
// processor's program, the wait points it keeps after elision, which tasks signal, the one
// readiness rule, and the serial twin's deadlock check of an explicit order.
#include "partition_plan.hpp"

#include <gtest/gtest.h>

#include <string>
#include <vector>

#include "partition_serial.hpp"
#include "random_graph.hpp"
#include "tgraph/graph/error.hpp"
#include "tgraph/graph/lowering.hpp"

namespace tgraph::replay {
namespace {

using detail::CombineRole;
using detail::OpKind;
using detail::PartitionPlan;
using detail::WaitKind;
using detail::WaitPoint;

using test::chain_graph;

// t0 writes d0; t1 reads d0, writes d1; t2 reads d1.
StepGraph three_task_chain() {
  return chain_graph(
      {{{0, AccessMode::W}}, {{0, AccessMode::R}, {1, AccessMode::W}}, {{1, AccessMode::R}}}, 2);
}

Assignment on(std::vector<ProcId> proc, std::uint32_t k) {
  Assignment a;
  a.k = k;
  a.proc = std::move(proc);
  return a;
}

// The tasks of processor p's program, in order.
std::vector<TaskId> tasks_of(const PartitionPlan& plan, ProcId p) {
  std::vector<TaskId> out;
  for (const detail::Op& op : plan.procs[p].ops)
    if (op.kind == OpKind::kTask) out.push_back(op.task);
  return out;
}

// The waits of task t in plan (on whichever processor runs it).
std::vector<WaitPoint> waits_of(const PartitionPlan& plan, TaskId t) {
  for (const auto& pp : plan.procs)
    for (const detail::Op& op : pp.ops)
      if (op.kind == OpKind::kTask && op.task == t)
        return {pp.waits.begin() + op.wait_begin, pp.waits.begin() + op.wait_end};
  return {};
}

bool signals(const PartitionPlan& plan, TaskId t) {
  for (const auto& pp : plan.procs)
    for (const detail::Op& op : pp.ops)
      if (op.kind == OpKind::kTask && op.task == t) return op.signal;
  return false;
}

TEST(PartitionPlan, WaitsOnlyForProducersOnOtherProcessors) {
  // t0 and t2 on processor 0, t1 on 1.
  const StepGraph g = three_task_chain();
  const Assignment a = on({0, 1, 0}, 2);
  const ExecGraph x = lower(g, &a, CwMode::kReduce);
  const PartitionPlan plan = detail::build_plan(x, 2, true, true);
  EXPECT_TRUE(plan.program_order);
  EXPECT_EQ(plan.rebuilt_procs, 2u);
  EXPECT_EQ(tasks_of(plan, 0), (std::vector<TaskId>{0, 2}));
  EXPECT_EQ(tasks_of(plan, 1), (std::vector<TaskId>{1}));
  EXPECT_TRUE(waits_of(plan, 0).empty());
  EXPECT_EQ(waits_of(plan, 1), (std::vector<WaitPoint>{{0, kNoLoop, WaitKind::kOnce}}));
  EXPECT_EQ(waits_of(plan, 2), (std::vector<WaitPoint>{{1, kNoLoop, WaitKind::kOnce}}));
  EXPECT_TRUE(signals(plan, 0));
  EXPECT_TRUE(signals(plan, 1));
  EXPECT_FALSE(signals(plan, 2));  // nobody waits for it
}

TEST(PartitionPlan, ElisionKeepsOnlyTheLastWaitOnEachProcessor) {
  // t0 and t1 on processor 1 write d0 and d1; t2 on processor 0 reads both. Program order on
  // processor 1 makes the wait for t1 imply the one for t0.
  const StepGraph g = chain_graph(
      {{{0, AccessMode::W}}, {{1, AccessMode::W}}, {{0, AccessMode::R}, {1, AccessMode::R}}}, 2);
  const Assignment a = on({1, 1, 0}, 2);
  const ExecGraph x = lower(g, &a, CwMode::kReduce);
  const PartitionPlan elided = detail::build_plan(x, 2, true, true);
  EXPECT_EQ(waits_of(elided, 2), (std::vector<WaitPoint>{{1, kNoLoop, WaitKind::kOnce}}));
  EXPECT_FALSE(signals(elided, 0));
  EXPECT_TRUE(signals(elided, 1));
  const PartitionPlan every = detail::build_plan(x, 2, true, false);
  EXPECT_EQ(waits_of(every, 2), (std::vector<WaitPoint>{{1, kNoLoop, WaitKind::kOnce},
                                                         {0, kNoLoop, WaitKind::kOnce}}));
  EXPECT_TRUE(signals(every, 0));
  EXPECT_FALSE(detail::same_programs(elided, every));
}

// The plain runs the executor runs as one loop: per task op, how many ops from it on wait for
// nothing and publish nothing (tasks only: a loop's begin and end ops cut a run).
std::vector<std::uint32_t> plain_runs(const PartitionPlan& plan, ProcId p) {
  std::vector<std::uint32_t> out;
  for (const detail::Op& op : plan.procs[p].ops) out.push_back(op.plain_run);
  return out;
}

TEST(PartitionPlan, PlainRunsStopAtAWaitASignalAndALoop) {
  // Processor 0: t0 (signals: t2 reads d0), t1, t3, t4; processor 1: t2 (waits for t0,
  // signals: t3 reads d1), t5. t3 waits for t2.
  const StepGraph g = chain_graph({{{0, AccessMode::W}},
                                   {{2, AccessMode::W}},
                                   {{0, AccessMode::R}, {1, AccessMode::W}},
                                   {{1, AccessMode::R}},
                                   {{2, AccessMode::R}},
                                   {{3, AccessMode::W}}},
                                  4);
  const Assignment a = on({0, 0, 1, 0, 0, 1}, 2);
  const PartitionPlan plan = detail::build_plan(lower(g, &a, CwMode::kReduce), 2, true, true);
  ASSERT_EQ(tasks_of(plan, 0), (std::vector<TaskId>{0, 1, 3, 4}));
  EXPECT_EQ(plain_runs(plan, 0), (std::vector<std::uint32_t>{0, 1, 0, 1}));
  EXPECT_EQ(plain_runs(plan, 1), (std::vector<std::uint32_t>{0, 1}));
  // One processor: nothing waits or signals; a loop's begin and end ops and its break task
  // (which publishes the loop's decision) cut the runs.
  StepGraph looped = chain_graph({{{0, AccessMode::W}},
                                  {{0, AccessMode::R}, {1, AccessMode::W}},
                                  {{1, AccessMode::R}, {2, AccessMode::W}},
                                  {{2, AccessMode::R}},
                                  {{0, AccessMode::R}}},
                                 3);
  for (TaskId t : {1u, 2u, 3u}) looped.tasks[t].loop = 0;
  looped.loops.push_back({2, 1, 4, 3, 0});
  looped.derive_edges();
  const Assignment one = on({0, 0, 0, 0, 0}, 1);
  const PartitionPlan single =
      detail::build_plan(lower(looped, &one, CwMode::kReduce), 1, true, true);
  // t0, loop begin, t1, t2, t3 (break), loop end, t4.
  EXPECT_EQ(plain_runs(single, 0), (std::vector<std::uint32_t>{1, 0, 2, 1, 0, 0, 1}));
}

TEST(PartitionPlan, ReadinessRuleCountsExecutionsByWaitKind) {
  const WaitPoint once{0, kNoLoop, WaitKind::kOnce};
  const WaitPoint same{0, 0, WaitKind::kSameIter};
  const WaitPoint prev{0, 0, WaitKind::kPrevIter};
  const WaitPoint after{0, 0, WaitKind::kAfterLoop};
  EXPECT_EQ(detail::needed_executions(once, 0, 0), 1u);
  EXPECT_EQ(detail::needed_executions(once, 5, 0), 1u);
  EXPECT_EQ(detail::needed_executions(same, 0, 0), 1u);
  EXPECT_EQ(detail::needed_executions(same, 3, 0), 4u);
  EXPECT_EQ(detail::needed_executions(prev, 0, 0), 0u);  // nothing before iteration 0
  EXPECT_EQ(detail::needed_executions(prev, 3, 0), 3u);
  EXPECT_EQ(detail::needed_executions(after, 0, 7), 7u);  // every iteration the loop ran
}

TEST(PartitionPlan, ExplicitOrderIsFollowedAndADeadlockingOneIsRejected) {
  // t0 -> t1 -> t2 through d0, d1; t3 independent. t0, t2, t3 on processor 0, t1 on 1.
  const StepGraph g = chain_graph({{{0, AccessMode::W}},
                                   {{0, AccessMode::R}, {1, AccessMode::W}},
                                   {{1, AccessMode::R}},
                                   {{2, AccessMode::W}}},
                                  3);
  Assignment a = on({0, 1, 0, 0}, 2);
  a.order = {{3, 0, 2}, {1}};
  const ExecGraph x = lower(g, &a, CwMode::kReduce);
  const PartitionPlan ok = detail::build_plan(x, 2, true, true);
  EXPECT_FALSE(ok.program_order);
  EXPECT_EQ(tasks_of(ok, 0), (std::vector<TaskId>{3, 0, 2}));
  EXPECT_NO_THROW(detail::check_deadlock_free(ok, x));
  EXPECT_EQ(tasks_of(detail::build_plan(x, 2, false, true), 0), (std::vector<TaskId>{0, 2, 3}));

  // t2 before t0 on processor 0: t2 waits for t1, which waits for t0.
  a.order = {{2, 0, 3}, {1}};
  const ExecGraph y = lower(g, &a, CwMode::kReduce);
  const PartitionPlan bad = detail::build_plan(y, 2, true, true);
  try {
    detail::check_deadlock_free(bad, y);
    ADD_FAILURE() << "no deadlock reported";
  } catch (const UsageError& e) {
    const std::string msg = e.what();
    EXPECT_NE(msg.find("deadlocks"), std::string::npos) << msg;
    EXPECT_NE(msg.find("processor 0 cannot run task 2"), std::string::npos) << msg;
    EXPECT_NE(msg.find("processor 1 cannot run task 1"), std::string::npos) << msg;
  }
}

TEST(PartitionPlan, SerialTwinRunsEveryTaskAndCountsItsWaits) {
  const StepGraph g = three_task_chain();
  const Assignment a = on({0, 1, 0}, 2);
  const ExecGraph x = lower(g, &a, CwMode::kReduce);
  const PartitionPlan plan = detail::build_plan(x, 2, true, true);
  struct Order : Workload {
    std::vector<TaskId> ran;
    void run(const TaskRun& r) override { ran.push_back(r.task); }
    bool stop_after(LoopId, std::uint32_t) override { return true; }
  } w;
  ExecStepStats stats;
  detail::run_interleaved(plan, x, &w, nullptr, &stats);
  EXPECT_EQ(w.ran, (std::vector<TaskId>{0, 1, 2}));
  ASSERT_EQ(stats.threads.size(), 2u);
  EXPECT_EQ(stats.threads[0].tasks, 2u);
  EXPECT_EQ(stats.threads[1].tasks, 1u);
  EXPECT_EQ(stats.waits(), 2u);
  EXPECT_EQ(stats.signals(), 2u);
}

// The ops of combine s that offer (one per producing processor).
std::vector<const detail::Op*> offers_of(const PartitionPlan& plan, std::uint32_t s) {
  std::vector<const detail::Op*> out;
  for (const auto& pp : plan.procs)
    for (const detail::Op& op : pp.ops)
      if (op.combine == CombineRole::kOffer && op.jump == s) out.push_back(&op);
  return out;
}

TEST(PartitionPlan, ADotProductsReducerAndScalarAreCombinedWithEachProcessorsLastPartial) {
  for (std::uint32_t k : {2u, 3u}) {
    const test::DotLoop d = test::dot_loop(6, k, 4, 0, 0);
    const ExecGraph x = lower(d.g, &d.a, CwMode::kReduce);
    PartitionPlan plan = detail::build_plan(x, k, true, true);
    detail::add_combines(x, plan);
    ASSERT_EQ(plan.combines.size(), 1u) << "k=" << k;
    const detail::Combine& c = plan.combines[0];
    EXPECT_EQ(c.home, 0u);
    EXPECT_EQ(c.parties, k);
    const std::vector<detail::Op>& ops = plan.procs[0].ops;
    ASSERT_EQ(c.end - c.head, 2u);  // the reducer, then the scalar (read on every processor)
    EXPECT_EQ(ops[c.head].combine, CombineRole::kHead);
    EXPECT_NE(x.reduction[ops[c.head].task], kNoReduction);
    EXPECT_EQ(x.graph.kind_name(ops[c.head + 1].task), "scalar");
    // Each other processor offers after its last partial sum.
    const auto offers = offers_of(plan, 0);
    ASSERT_EQ(offers.size(), k - 1);
    for (ProcId q = 1; q < k; ++q) {
      TaskId last = kNoTask;
      for (const detail::Op& op : plan.procs[q].ops)
        if (op.kind == OpKind::kTask && x.graph.kind_name(op.task) == "partial") last = op.task;
      EXPECT_EQ(offers[q - 1]->task, last) << "k=" << k << " processor " << q;
    }
    // Without elision a reducer waits for every writer: no combine.
    PartitionPlan every = detail::build_plan(x, k, true, false);
    detail::add_combines(x, every);
    EXPECT_TRUE(every.combines.empty());
  }
}

TEST(PartitionPlan, AReductionOutsideLoopsIsCombinedToo) {
  // t0, t1, t2 add into d0 on processors 0, 1, 2; t3 reads it (processor 0) and writes d1,
  // which t4 reads on processor 1: the reducer and t3 are the combine.
  const StepGraph g = chain_graph({{{0, AccessMode::CW}},
                                   {{0, AccessMode::CW}},
                                   {{0, AccessMode::CW}},
                                   {{0, AccessMode::R}, {1, AccessMode::W}},
                                   {{1, AccessMode::R}}},
                                  2);
  const Assignment a = on({0, 1, 2, 0, 1}, 3);
  const ExecGraph x = lower(g, &a, CwMode::kReduce);
  PartitionPlan plan = detail::build_plan(x, 3, true, true);
  detail::add_combines(x, plan);
  ASSERT_EQ(plan.combines.size(), 1u);
  EXPECT_EQ(plan.combines[0].parties, 3u);
  EXPECT_EQ(plan.combines[0].end - plan.combines[0].head, 2u);
  const auto offers = offers_of(plan, 0);
  ASSERT_EQ(offers.size(), 2u);
  EXPECT_EQ(offers[0]->task, x.exec_of[1]);
  EXPECT_EQ(offers[1]->task, x.exec_of[2]);
}

TEST(PartitionPlan, CombinesOfRandomGraphsHaveAReducerHeadAndOneOfferPerOtherProcessor) {
  std::size_t combines = 0;
  for (std::uint32_t seed = 1; seed <= 40; ++seed) {
    const StepGraph g = test::random_graph(seed * 7919);
    for (std::uint32_t k : {2u, 3u, 5u}) {
      const Assignment a = test::random_assignment(g, k, seed);
      const ExecGraph x = lower(g, &a, CwMode::kReduce);
      PartitionPlan plan = detail::build_plan(x, k, true, true);
      detail::add_combines(x, plan);
      combines += plan.combines.size();
      for (std::uint32_t s = 0; s < plan.combines.size(); ++s) {
        const detail::Combine& c = plan.combines[s];
        const detail::ProcPlan& home = plan.procs[c.home];
        const detail::Op& head = home.ops[c.head];
        EXPECT_EQ(head.combine, CombineRole::kHead);
        EXPECT_EQ(head.jump, s);
        EXPECT_NE(x.reduction[head.task], kNoReduction);
        EXPECT_EQ(head.wait_end - head.wait_begin, c.parties - 1);
        for (std::uint32_t i = c.head + 1; i < c.end; ++i) {
          EXPECT_EQ(home.ops[i].wait_begin, home.ops[i].wait_end);
          EXPECT_TRUE(home.ops[i].signal);
          EXPECT_FALSE(home.ops[i].is_break);
        }
        std::vector<ProcId> procs;
        for (const detail::Op* op : offers_of(plan, s)) {
          const ProcId q = x.assignment.proc[op->task];
          EXPECT_NE(q, c.home);
          EXPECT_EQ(std::count(procs.begin(), procs.end(), q), 0);
          procs.push_back(q);
          bool waited = false;
          for (auto i = head.wait_begin; i < head.wait_end; ++i)
            waited |= home.waits[i].producer == op->task;
          EXPECT_TRUE(waited) << "seed " << seed << " k " << k;
        }
        EXPECT_EQ(procs.size() + 1, c.parties);
      }
    }
  }
  EXPECT_GT(combines, 20u);  // the random graphs do exercise them
}

}  // namespace
}  // namespace tgraph::replay
