// SPDX-License-Identifier: MIT
// The observers: the timeline names each step's task kinds from that step's graph and keeps
// at most the steps asked for; per-thread counters add up to the step's task instances.
#include "tgraph/replay/observer.hpp"

#include <gtest/gtest.h>

#include <set>
#include <string>

#include "random_graph.hpp"
#include "tgraph/replay/executor.hpp"
#include "tgraph/replay/synthetic.hpp"

namespace tgraph::replay {
namespace {

// `n` independent tasks of kind `kind` on data of their own.
StepGraph independent(const std::string& kind, std::uint32_t n) {
  StepGraph g;
  g.intern_kind("unused");  // kind ids differ from the other graph's
  const KindId k = g.intern_kind(kind);
  for (std::uint32_t i = 0; i < n; ++i) {
    g.data.push_back({"d" + std::to_string(i), kNoObject, 64});
    const Access acc[] = {{i, AccessMode::RW}};
    g.add_task(k, kNoObject, acc, 1000);
  }
  g.derive_edges();
  return g;
}

TEST(TimelineObserver, NamesEachStepsKindsFromThatStepsGraph) {
  const StepGraph a = independent("first", 3), b = independent("second", 5);
  auto ex = make_executor(Policy::kPartition, test::partition_options(2));
  TimelineObserver timeline;
  StatsObserver stats;
  ex->add_observer(timeline);
  ex->add_observer(stats);
  SyntheticWorkload w({.cost_scale = 0.0});
  for (const StepGraph* g : {&a, &b}) {
    const Assignment as = test::random_assignment(*g, 2, 1);
    w.set_step(*g);
    ex->run_step(*g, &as, w);
    std::uint64_t counted = 0;
    for (const StatsObserver::Thread& t : stats.threads()) counted += t.tasks;
    EXPECT_EQ(counted, g->tasks.size());
  }
  const Timeline& t = timeline.timeline();
  EXPECT_EQ(t.steps, 2u);
  EXPECT_EQ(t.threads, 2u);
  ASSERT_EQ(t.tasks.size(), 8u);
  std::set<TaskId> seen[2];
  for (const TimelineTask& e : t.tasks) {
    ASSERT_LT(e.step, 2u);
    EXPECT_EQ(e.kind, e.step == 0 ? "first" : "second") << "task " << e.task;
    ASSERT_TRUE(e.origin.has_value());
    seen[e.step].insert(*e.origin);
    EXPECT_LE(e.start_ns, e.end_ns);
  }
  EXPECT_EQ(seen[0].size(), 3u);
  EXPECT_EQ(seen[1].size(), 5u);
  // Step by step, by start time within a step.
  for (std::size_t i = 1; i < t.tasks.size(); ++i)
    EXPECT_TRUE(t.tasks[i - 1].step < t.tasks[i].step ||
                (t.tasks[i - 1].step == t.tasks[i].step &&
                 t.tasks[i - 1].start_ns <= t.tasks[i].start_ns));
}

TEST(TimelineObserver, KeepsAtMostTheStepsAskedFor) {
  const StepGraph g = independent("k", 4);
  auto ex = make_executor(Policy::kSequential, {});
  TimelineObserver timeline;
  timeline.set_max_steps(1);
  ex->add_observer(timeline);
  SyntheticWorkload w({.cost_scale = 0.0});
  w.set_step(g);
  for (int s = 0; s < 3; ++s) ex->run_step(g, nullptr, w);
  EXPECT_EQ(timeline.timeline().steps, 3u);
  ASSERT_EQ(timeline.timeline().tasks.size(), 4u);
  for (const TimelineTask& e : timeline.timeline().tasks) EXPECT_EQ(e.step, 0u);
}

}  // namespace
}  // namespace tgraph::replay
