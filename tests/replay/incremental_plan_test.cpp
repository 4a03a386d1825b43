// SPDX-License-Identifier: MIT
// The partition executor's incremental plan update (replay/src/partition_update.cpp): on
// every structure or assignment change the updated plan equals a from-scratch build,
// processors whose tasks and waits did not change keep their program, and the steps run
// in dependency order and give the sequential state.
#include <gtest/gtest.h>

#include <random>
#include <stdexcept>
#include <vector>

#include "partition_plan.hpp"
#include "random_graph.hpp"
#include "tgraph/replay/executor.hpp"
#include "tgraph/replay/synthetic.hpp"

namespace tgraph::replay {
namespace {

// `g` without task `drop` (ids after it shift down; keys kept), edges derived again.
StepGraph without(const StepGraph& g, TaskId drop) {
  StepGraph h;
  h.kinds = g.kinds;
  h.objects = g.objects;
  h.data = g.data;
  for (TaskId t = 0; t < g.tasks.size(); ++t) {
    if (t == drop) continue;
    const TaskId id = h.add_task(g.tasks[t].kind, g.tasks[t].object, g.accesses_of(t),
                                 g.tasks[t].cost_ns, g.tasks[t].key);
    h.tasks[id].loop = g.tasks[t].loop;
  }
  h.loops = g.loops;
  for (Loop& l : h.loops) {
    if (l.first > drop) --l.first;
    if (l.last > drop) --l.last;
  }
  h.derive_edges();
  return h;
}

// A removable task: not a loop's break or condition writer (the last two of a body).
TaskId removable(const StepGraph& g, std::mt19937& rng) {
  for (;;) {
    const auto t = static_cast<TaskId>(rng() % g.tasks.size());
    const LoopId l = g.tasks[t].loop;
    if (l == kNoLoop || t + 2 < g.loops[l].last) return t;
  }
}

// A random topological order of g's tasks, each loop one block in program order (what
// `list` produces: every processor's order is a restriction of one global order).
std::vector<TaskId> random_order(const StepGraph& g, std::mt19937& rng) {
  const auto n = static_cast<TaskId>(g.tasks.size());
  auto unit = [&](TaskId t) { return g.tasks[t].loop == kNoLoop ? t : g.loops[g.tasks[t].loop].first; };
  std::vector<std::vector<TaskId>> succ(n);
  std::vector<std::uint32_t> indeg(n, 0);
  for (const Edge& e : g.edges) {
    const TaskId a = unit(e.from), b = unit(e.to);
    if (a == b) continue;
    succ[a].push_back(b);
    ++indeg[b];
  }
  std::vector<TaskId> ready, order;
  for (TaskId t = 0; t < n; ++t)
    if (unit(t) == t && indeg[t] == 0) ready.push_back(t);
  while (!ready.empty()) {
    const std::size_t i = rng() % ready.size();
    const TaskId u = ready[i];
    ready.erase(ready.begin() + static_cast<std::ptrdiff_t>(i));
    if (g.tasks[u].loop == kNoLoop) {
      order.push_back(u);
    } else {
      for (TaskId v = u; v < g.loops[g.tasks[u].loop].last; ++v) order.push_back(v);
    }
    for (TaskId v : succ[u])
      if (--indeg[v] == 0) ready.push_back(v);
  }
  EXPECT_EQ(order.size(), g.tasks.size());
  return order;
}

struct Sequence {
  std::vector<StepGraph> graphs;
  std::vector<Assignment> assignments;
};

// Steps of a random program: each drops a task and/or moves a few tasks to other
// processors (as a contact change and sticky's placement would), sometimes with an explicit
// per-processor order.
Sequence random_sequence(std::uint32_t seed, std::uint32_t k, int steps) {
  std::mt19937 rng(seed);
  Sequence s;
  StepGraph g = test::random_graph(seed, 6, 10, 10);
  Assignment a = test::random_assignment(g, k, seed);
  for (int step = 0; step < steps; ++step) {
    Assignment b = a;
    if (rng() % 3 == 0) {
      b.order.assign(k, {});
      for (TaskId t : random_order(g, rng)) b.order[b.proc[t]].push_back(t);
    }
    s.graphs.push_back(g);
    s.assignments.push_back(b);
    const auto what = rng() % 3;
    if (what != 1 && g.tasks.size() > 20) {
      const TaskId drop = removable(g, rng);
      g = without(g, drop);
      a.proc.erase(a.proc.begin() + drop);
    }
    if (what != 0)
      for (int i = 0; i < 2; ++i) a.proc[rng() % a.proc.size()] = static_cast<ProcId>(rng() % k);
  }
  return s;
}

TEST(IncrementalPlan, EqualsAFullBuildOnRandomSequences) {
  std::uint64_t updates = 0, partial = 0;
  for (std::uint32_t k : {2u, 3u, 5u, 8u}) {
    for (std::uint32_t seed = 1; seed <= 8; ++seed) {
      const Sequence s = random_sequence(seed * 31 + k, k, 12);
      for (const bool elide : {true, false}) {
        detail::PartitionPlan previous;
        for (std::size_t i = 0; i < s.graphs.size(); ++i) {
          const ExecGraph x = lower(s.graphs[i], &s.assignments[i], CwMode::kReduce);
          detail::PartitionPlan full = detail::build_plan(x, k, true, elide);
          if (i > 0) {
            detail::PartitionPlan updated = detail::update_plan(x, previous, k, true, elide);
            EXPECT_TRUE(detail::same_programs(updated, full))
                << "k " << k << " seed " << seed << " step " << i << " elide " << elide;
            EXPECT_LE(updated.rebuilt_procs, k);
            partial += updated.rebuilt_procs < k ? 1 : 0;
            ++updates;
            full = std::move(updated);  // the executor updates its previous updated plan
          }
          previous = std::move(full);
        }
      }
    }
  }
  // Small changes leave some processors' programs as they were (new random orders rebuild
  // every processor whose order changed).
  EXPECT_GT(partial, updates / 8);
}

TEST(IncrementalPlan, RunsRandomSequencesInDependencyOrder) {
  std::uint64_t steps = 0, partial = 0;
  for (std::uint32_t k : {2u, 3u, 5u, 8u}) {
    for (std::uint32_t seed = 1; seed <= 8; ++seed) {
      const Sequence s = random_sequence(seed * 31 + k, k, 12);
      auto ex = make_executor(Policy::kPartition, test::partition_options(k, true));
      TimelineObserver timeline;
      ex->add_observer(timeline);
      SyntheticWorkload w({.cost_scale = 0.0});
      for (std::size_t i = 0; i < s.graphs.size(); ++i) {
        w.set_step(s.graphs[i]);
        ExecStepStats st;
        ASSERT_NO_THROW(st = ex->run_step(s.graphs[i], &s.assignments[i], w))
            << "k " << k << " seed " << seed << " step " << i;
        if (st.rebuilt) {  // (a step that changed nothing reuses the cached plan)
          EXPECT_LE(st.rebuilt_procs, k);
          if (i > 0 && st.rebuilt_procs < k) ++partial;
          ++steps;
        }
        test::expect_valid_order(ex->last_exec()->graph, timeline.timeline().tasks,
                                 static_cast<std::uint32_t>(i), {.exec = true});
        if (::testing::Test::HasFailure()) return;
      }
    }
  }
  // Small changes leave some processors' programs as they were (new random orders rebuild
  // every processor whose order changed).
  EXPECT_GT(partial, steps / 8);
}

TEST(IncrementalPlan, MovingASinkTaskRebuildsOnlyTheTwoProcessorsInvolved) {
  // A task that no other task depends on moves to another processor: only the two
  // processors whose task lists changed are rebuilt. The first random program with such a
  // task: outside loops, no successor, no CW access (its move could change a reducer).
  StepGraph g;
  TaskId t = kNoTask;
  for (std::uint32_t seed = 1; seed < 100 && t == kNoTask; ++seed) {
    g = test::random_graph(seed, 6, 10, 10);
    std::vector<bool> has_succ(g.tasks.size(), false);
    for (const Edge& e : g.edges) has_succ[e.from] = true;
    for (const Edge& e : g.carried_edges) has_succ[e.from] = true;
    for (TaskId u = 0; u < g.tasks.size() && t == kNoTask; ++u) {
      bool cw = false;
      for (const Access& acc : g.accesses_of(u)) cw = cw || acc.mode == AccessMode::CW;
      if (g.tasks[u].loop == kNoLoop && !has_succ[u] && !cw) t = u;
    }
  }
  ASSERT_NE(t, kNoTask);
  const std::uint32_t k = 4;
  const Assignment a = test::random_assignment(g, k, 5);
  auto ex = make_executor(Policy::kPartition, test::partition_options(k, true));
  SyntheticWorkload w({.cost_scale = 0.0});
  w.set_step(g);
  EXPECT_EQ(ex->run_step(g, &a, w).rebuilt_procs, k);  // first plan: from scratch
  Assignment b = a;
  b.proc[t] = (a.proc[t] + 1) % k;
  const ExecStepStats s = ex->run_step(g, &b, w);
  EXPECT_TRUE(s.rebuilt);
  EXPECT_EQ(s.rebuilt_procs, 2u);
  EXPECT_GT(s.rebuild_ns, 0);
  EXPECT_GE(s.build_ns, s.rebuild_ns);
}

TEST(IncrementalPlan, OffBuildsEveryProcessor) {
  const Sequence s = random_sequence(77, 3, 6);
  ExecOptions o;
  o.threads = 3;
  o.partition.serial = true;
  o.incremental_plans = false;
  auto ex = make_executor(Policy::kPartition, o);
  SyntheticWorkload w({.cost_scale = 0.0});
  for (std::size_t i = 0; i < s.graphs.size(); ++i) {
    w.set_step(s.graphs[i]);
    EXPECT_EQ(ex->run_step(s.graphs[i], &s.assignments[i], w).rebuilt_procs, 3u);
  }
}

}  // namespace
}  // namespace tgraph::replay
