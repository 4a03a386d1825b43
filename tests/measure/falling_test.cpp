// SPDX-License-Identifier: MIT
// Sticky on a real capture of the `falling` scene (collision groups merge and split, through
// measure::capture_trace): fewer moved tasks than METIS relabelled every step, fallbacks
// exercised. Here rather than in tests/partition, which does not link the engine.
#include <gtest/gtest.h>

#include "tgraph/graph/diff.hpp"
#include "tgraph/measure/capture.hpp"
#include "tgraph/partition/compare.hpp"
#include "tgraph/partition/evaluate.hpp"
#include "tgraph/partition/strategy.hpp"

namespace tgraph::partition {
namespace {

const Trace& falling_trace() {
  static const Trace trace = measure::capture_trace(
      "falling", static_cast<std::uint32_t>(samples::make_scene("falling")->default_steps()));
  return trace;
}

TEST(StickyOnFalling, MovesFewerTasksThanMetisRelabelledEveryStep) {
  const Trace& trace = falling_trace();
  std::size_t loop_changes = 0;
  for (std::size_t s = 1; s < trace.steps.size(); ++s)
    loop_changes += trace.steps[s].loops.size() != trace.steps[s - 1].loops.size() ? 1 : 0;
  ASSERT_GE(loop_changes, 2u) << "the capture should merge collision groups";
  for (std::uint32_t k : {2u, 4u, 8u}) {
    const TracePartition sticky = partition_trace(trace, "sticky", k);
    const TracePartition relabel = partition_trace(trace, "metis-relabel", k);
    const TracePartition metis = partition_trace(trace, "metis", k);
    const PartitionSummary s = summarize(sticky.stats), r = summarize(relabel.stats),
                           m = summarize(metis.stats);
    EXPECT_LT(s.moved_tasks, r.moved_tasks) << "k " << k;
    // Relabelling never moves more than METIS's own labels, step by step.
    for (std::size_t i = 0; i < trace.steps.size(); ++i)
      ASSERT_LE(relabel.stats[i].moved_tasks, metis.stats[i].moved_tasks)
          << "k " << k << " step " << i;
    EXPECT_LE(r.moved_tasks, m.moved_tasks);
    // Every change of the number of solver loops is a fallback; the other steps are not.
    EXPECT_GE(s.fallback_steps, loop_changes);
    for (std::size_t i = 1; i < trace.steps.size(); ++i) {
      if (trace.steps[i].loops.size() != trace.steps[i - 1].loops.size()) {
        EXPECT_TRUE(sticky.stats[i].fallback) << "k " << k << " step " << i;
      }
    }
    EXPECT_GT(s.reused_steps, trace.steps.size() / 2);
    // The assignments are valid for the trace (processor range, sizes, orders).
    EXPECT_NO_THROW(check_fits(trace, sticky.assignment, "sticky"));
    EXPECT_NO_THROW(check_fits(trace, relabel.assignment, "metis-relabel"));
    // metis-relabel is METIS renamed: the same cut every step.
    for (std::size_t i = 0; i < trace.steps.size(); ++i)
      ASSERT_EQ(relabel.stats[i].edgecut, metis.stats[i].edgecut) << "step " << i;
  }
}

TEST(StickyOnFalling, RepartitioningAtMergesMovesFewerTasksThanMetisRelabel) {
  const Trace& trace = falling_trace();
  Options o;
  o.sticky_fallback = StickyFallback::kRepartition;
  for (std::uint32_t k : {2u, 4u, 8u}) {
    const TracePartition sticky = partition_trace(trace, "sticky", k, o);
    const TracePartition relabel = partition_trace(trace, "metis-relabel", k);
    const PartitionSummary s = summarize(sticky.stats);
    EXPECT_LT(s.moved_tasks, summarize(relabel.stats).moved_tasks) << "k " << k;
    EXPECT_GE(s.fallback_steps, 2u);
    EXPECT_NO_THROW(check_fits(trace, sticky.assignment, "sticky"));
  }
}

TEST(StickyOnFalling, RefiningAtMergesMovesAQuarterOfMetisRelabelsTasksAtMetissMakespan) {
  // Issue 13's targets on a real capture: moved tasks at most a quarter of metis-relabel's;
  // the predicted makespan is guarded against gross regressions only (within 25 % of
  // METIS's): the captured costs are measured, and under a loaded ctest their noise alone
  // moved the ratio by 10 % (docs/partitioning.md has the measured -3 to -9 %).
  const Trace& trace = falling_trace();
  for (std::uint32_t k : {2u, 4u, 8u}) {
    const TracePartition sticky = partition_trace(trace, "sticky", k);
    const TracePartition relabel = partition_trace(trace, "metis-relabel", k);
    EXPECT_LE(4 * summarize(sticky.stats).moved_tasks, summarize(relabel.stats).moved_tasks) << k;
    const model::CostModel model = model::CostModel::defaults();
    const double s =
        static_cast<double>(evaluate(trace, sticky.assignment, model).total.makespan_ns);
    const double m =
        static_cast<double>(evaluate(trace, relabel.assignment, model).total.makespan_ns);
    EXPECT_LE(s, 1.25 * m) << "k " << k;
    EXPECT_NO_THROW(check_fits(trace, sticky.assignment, "sticky"));
  }
}

TEST(DiffOnFalling, NamesTheContactThatMergedTheGroupsAtEveryMerge) {
  const Trace& trace = falling_trace();
  int merges = 0;
  for (std::size_t s = 1; s < trace.steps.size(); ++s) {
    const StepGraph &a = trace.steps[s - 1], &b = trace.steps[s];
    const StepDiff d = diff_steps(a, b);
    EXPECT_EQ(d.same_structure, b.same_structure(a));
    if (b.loops.size() >= a.loops.size()) continue;
    ++merges;
    // Solver loops merged: groups merged, by contacts that appeared this step, and every
    // added contact's tasks say which contact they belong to.
    ASSERT_FALSE(d.groups_merged.empty()) << "step " << s;
    ASSERT_FALSE(d.contacts_added.empty()) << "step " << s;
    for (const GroupChange& g : d.groups_merged) {
      EXPECT_GE(g.from.size(), 2u);
      ASSERT_FALSE(g.contacts.empty()) << "step " << s;
      for (const std::string& c : g.contacts)
        EXPECT_NE(std::find(d.contacts_added.begin(), d.contacts_added.end(), c),
                  d.contacts_added.end());
    }
    std::size_t caused = 0;
    for (const TaskRef& t : d.tasks_added) caused += t.caused_by.empty() ? 0 : 1;
    EXPECT_GE(caused, d.contacts_added.size()) << "step " << s;
  }
  EXPECT_GE(merges, 2);
}

}  // namespace
}  // namespace tgraph::partition
