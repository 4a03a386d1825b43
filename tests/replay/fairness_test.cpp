// SPDX-License-Identifier: MIT
// Fair baselines: every policy reduces CW groups in parallel by default, and says so.
#include <gtest/gtest.h>

#include <algorithm>
#include <set>

#include "tgraph/replay/executor.hpp"
#include "tgraph/replay/observer.hpp"
#include "tgraph/replay/synthetic.hpp"

namespace tgraph::replay {
namespace {

/// x is written, then `writers` tasks add into y (CW) reading x, then one task reads y.
StepGraph cw_group(int writers, std::uint64_t cost_ns) {
  StepGraph g;
  const KindId init = g.intern_kind("init"), add = g.intern_kind("add"),
               use = g.intern_kind("use");
  for (int i = 0; i < writers; ++i) g.objects.push_back({"o" + std::to_string(i)});
  g.data = {{"x", kNoObject, 4096}, {"y", kNoObject, 4096}, {"z", kNoObject, 64}};
  g.add_task(init, 0, std::vector<Access>{{0, AccessMode::W}}, 1000, 1);
  for (int i = 0; i < writers; ++i)
    g.add_task(add, static_cast<ObjectId>(i),
               std::vector<Access>{{0, AccessMode::R}, {1, AccessMode::CW}}, cost_ns,
               static_cast<StableKey>(i + 2));
  g.add_task(use, 0, std::vector<Access>{{1, AccessMode::R}, {2, AccessMode::W}}, 1000, 999);
  g.derive_edges();
  return g;
}

class DynamicBaseline : public ::testing::TestWithParam<Policy> {};

// The fairness bug this guards against: baselines that turned every CW into RW ran the
// writers of one datum one after the other.
TEST_P(DynamicBaseline, RunsCwWritersOfOneDatumOnTwoThreadsAtOnce) {
  ExecOptions o;
  o.threads = 2;
  auto ex = make_executor(GetParam(), o);
  EXPECT_EQ(ex->cw(), CwMode::kReduce);
  EXPECT_EQ(ex->scope(), ReduceScope::kPerWriter);
  // Whether the second thread gets to steal a writer while the first runs depends on the
  // machine's load (a loaded 2-core machine under TSan may not schedule it for 32 ms; at load
  // average 15, five steps once saw none). What holds under any load is checked at every
  // step: no edge orders one writer after another, each but the first has its temporary, the
  // reader follows the reducer. The overlap itself is retried with longer writers (4 ms, then
  // 16, 64 and 256 ms each, three steps of each length) until one step shows two writers
  // running at once on two threads: a policy that serialized the writers never would.
  TimelineObserver timeline;
  ex->add_observer(timeline);
  bool overlap = false;
  std::uint32_t step_no = 0;
  for (std::uint64_t cost = 4'000'000; cost <= 256'000'000 && !overlap; cost *= 4) {
    const StepGraph g = cw_group(8, cost);
    SyntheticWorkload w;
    w.set_step(g);
    for (int attempt = 0; attempt < 3 && !overlap; ++attempt, ++step_no) {
      ex->run_step(g, nullptr, w);
      const ExecGraph& x = *ex->last_exec();
      ASSERT_EQ(x.reductions.size(), 1u);
      EXPECT_EQ(x.reductions[0].temps.size(), 7u);  // the first writer adds into y itself
      EXPECT_FALSE(x.added_edges);
      std::set<TaskId> exec_writers;
      for (TaskId t = 0; t < x.origin.size(); ++t)
        if (x.origin[t] != kNoTask && g.kind_name(x.origin[t]) == "add") exec_writers.insert(t);
      ASSERT_EQ(exec_writers.size(), 8u);
      for (const Edge& e : x.graph.edges)
        EXPECT_FALSE(exec_writers.count(e.from) && exec_writers.count(e.to))
            << "an edge orders writer " << e.from << " before writer " << e.to;
      std::vector<TimelineTask> step;
      for (const TimelineTask& e : timeline.timeline().tasks)
        if (e.step == step_no) step.push_back(e);
      std::vector<TimelineTask> writers;
      for (const TimelineTask& e : step)
        if (e.origin.has_value() && g.kind_name(*e.origin) == "add") writers.push_back(e);
      ASSERT_EQ(writers.size(), 8u);
      for (const auto& a : writers)
        for (const auto& b : writers)
          if (a.thread != b.thread && a.start_ns < b.end_ns && b.start_ns < a.end_ns)
            overlap = true;
      // The reader ran after every writer and after the reducer.
      std::int64_t last_writer_end = 0, reducer_end = 0, reader_start = 0;
      for (const TimelineTask& e : step) {
        if (!e.origin) reducer_end = e.end_ns;
        else if (g.kind_name(*e.origin) == "add")
          last_writer_end = std::max(last_writer_end, e.end_ns);
        else if (g.kind_name(*e.origin) == "use") reader_start = e.start_ns;
      }
      EXPECT_GE(reader_start, reducer_end);
      EXPECT_GE(reducer_end, last_writer_end);
    }
  }
  EXPECT_TRUE(overlap) << "no two CW writers of y ran at the same time on two threads in "
                       << step_no << " steps, writers up to 256 ms each";
}

TEST_P(DynamicBaseline, SerializeIsStillAvailableAndOrdersTheWriters) {
  const StepGraph g = cw_group(4, 1000);
  ExecOptions o;
  o.threads = 2;
  o.cw = CwMode::kSerialize;
  auto ex = make_executor(GetParam(), o);
  EXPECT_EQ(ex->cw(), CwMode::kSerialize);
  SyntheticWorkload w({.cost_scale = 0.0});
  w.set_step(g);
  ex->run_step(g, nullptr, w);
  EXPECT_TRUE(ex->last_exec()->reductions.empty());
  EXPECT_TRUE(ex->last_exec()->added_edges);
}

INSTANTIATE_TEST_SUITE_P(Policies, DynamicBaseline,
                         ::testing::Values(Policy::kWorksteal, Policy::kBarrier,
                                           Policy::kOmpTasks),
                         [](const auto& p) {
                           std::string name(to_string(p.param));
                           std::replace(name.begin(), name.end(), '-', '_');  // gtest names
                           return name;
                         });

// Sum of the synthetic CW bodies is exact integer arithmetic: every policy and scope must
// reach the sequential result, and the per-writer reducer must add each temporary once.
TEST(FairReduction, EveryPolicyReachesTheSequentialSums) {
  const StepGraph g = cw_group(6, 0);
  auto run = [&](Policy p, std::uint32_t k) {
    ExecOptions o;
    o.threads = k;
    auto ex = make_executor(p, o);
    SyntheticWorkload w({.cost_scale = 0.0});
    w.set_step(g);
    Assignment a;
    a.k = k;
    for (TaskId t = 0; t < g.tasks.size(); ++t) a.proc.push_back(t % k);
    for (int s = 0; s < 3; ++s) ex->run_step(g, p == Policy::kPartition ? &a : nullptr, w);
    auto y = w.words(1);
    return std::vector<std::uint64_t>(y.begin(), y.end());
  };
  const auto want = run(Policy::kSequential, 1);
  for (Policy p : {Policy::kPartition, Policy::kWorksteal, Policy::kBarrier, Policy::kOmpTasks})
    for (std::uint32_t k : {2u, 3u}) EXPECT_EQ(run(p, k), want) << to_string(p) << " k=" << k;
}

// The barrier baseline: a CW group is one parallel phase (plus one reduction phase), not a
// phase per writer.
TEST(FairReduction, BarrierRunsACwGroupAsOnePhase) {
  const StepGraph g = cw_group(16, 0);
  // Barriers each thread passes: by operation, init | 16 writers | reducer | reader, one
  // barrier after each; by omp-for, none between the reducer and the reader (both on thread
  // 0, the reader needs nothing else).
  for (const auto& [rule, barriers] :
       {std::pair{BarrierRule::kOperation, 4u}, std::pair{BarrierRule::kOmpFor, 3u}}) {
    ExecOptions o;
    o.threads = 2;
    o.barrier.rule = rule;
    auto ex = make_executor(Policy::kBarrier, o);
    SyntheticWorkload w({.cost_scale = 0.0});
    w.set_step(g);
    const ExecStepStats s = ex->run_step(g, nullptr, w);
    for (const ThreadCounters& t : s.threads) EXPECT_EQ(t.waits, barriers) << to_string(rule);
  }
}

}  // namespace
}  // namespace tgraph::replay
