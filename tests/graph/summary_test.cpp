// SPDX-License-Identifier: MIT
// The trace summary `tgraph info` prints: totals, per-step lines, contact changes, JSON, text.
#include "tgraph/graph/summary.hpp"

#include <gtest/gtest.h>

#include <nlohmann/json.hpp>

#include "tgraph/graph/generate.hpp"
#include "tgraph/graph/metrics.hpp"

namespace tgraph {
namespace {

using M = AccessMode;

// Two bodies; with `touching` a contact task and one shared group, and a solver loop of
// `iterations` (the break reads the condition written in the body).
StepGraph step(bool touching, std::uint32_t iterations, std::uint64_t cost) {
  StepGraph g;
  g.kinds = {"op", "loop.break"};
  g.objects = {{"a"}, {"b"}};
  g.data = {{"xa", 0, 64}, {"xb", 1, 64}, {"cond", kNoObject, 1}};
  const Access wa[] = {{0, M::RW}}, wb[] = {{1, M::RW}}, body[] = {{0, M::RW}, {2, M::W}},
               brk[] = {{2, M::R}}, both[] = {{0, M::CW}, {1, M::CW}};
  g.add_task(0, 0, wa, cost, 1);
  g.add_task(0, 1, wb, cost, 2);
  if (touching) {
    g.add_task(0, kNoObject, both, cost, 3);
    g.contacts = {{0, 1}};
    g.groups = {0, 0};
  } else {
    g.groups = {0, 1};
  }
  const TaskId first = g.add_task(0, 0, body, 2 * cost, 4);
  g.add_task(1, kNoObject, brk, 1, 5);
  g.tasks[first].loop = g.tasks[first + 1].loop = 0;
  g.loops.push_back({2, first, first + 2, iterations, 100});
  g.derive_edges();
  return g;
}

TEST(TraceSummary, AddsUpTheStepsMetricsAndCountsContactChanges) {
  Trace t;
  t.header.scene = "two";
  t.steps = {step(false, 3, 10), step(false, 4, 12), step(true, 7, 10), step(true, 2, 10),
             step(false, 3, 10)};
  const TraceSummary s = summarize_trace(t);
  EXPECT_EQ(s.steps, 5u);
  ASSERT_EQ(s.per_step.size(), 5u);
  std::uint64_t tasks = 0, work = 0, span = 0, edges = 0;
  for (std::size_t i = 0; i < t.steps.size(); ++i) {
    const Metrics m = compute_metrics(t.steps[i]);
    EXPECT_EQ(s.per_step[i].tasks, m.tasks);
    EXPECT_EQ(s.per_step[i].work_ns, m.work_ns);
    EXPECT_EQ(s.per_step[i].span_ns, m.span_ns);
    EXPECT_EQ(s.per_step[i].structure, t.steps[i].structural_hash());
    tasks += m.tasks;
    work += m.work_ns;
    span += m.span_ns;
    edges += m.edges;
  }
  EXPECT_EQ(s.tasks, tasks);
  EXPECT_EQ(s.work_ns, work);
  EXPECT_EQ(s.span_ns, span);
  EXPECT_EQ(s.edges, edges);
  EXPECT_DOUBLE_EQ(s.parallelism, static_cast<double>(work) / static_cast<double>(span));
  EXPECT_EQ(s.tasks_min, 4u);
  EXPECT_EQ(s.tasks_max, 5u);
  EXPECT_DOUBLE_EQ(s.tasks_mean, 22.0 / 5.0);
  EXPECT_EQ(s.loops, 5u);
  EXPECT_EQ(s.loop_iterations, 3u + 4 + 7 + 2 + 3);
  EXPECT_EQ(s.max_loop_iterations, 7u);
  EXPECT_EQ(s.per_step[2].loop_iterations, (std::vector<std::uint32_t>{7}));
  // Contacts appear at step 2 and vanish at step 4; costs alone change no structure.
  std::vector<bool> changed;
  for (const StepSummary& st : s.per_step) changed.push_back(st.contacts_changed);
  EXPECT_EQ(changed, (std::vector<bool>{false, false, true, false, true}));
  EXPECT_EQ(s.contact_changes, 2u);
  EXPECT_EQ(s.distinct_structures, 2u);
  EXPECT_EQ(s.per_step[0].collision_groups, 2u);
  EXPECT_EQ(s.per_step[2].collision_groups, 1u);
  EXPECT_EQ(s.last_step_collision_groups, 2u);
  // The structure changed where the contact appeared and vanished, each with its diff.
  std::vector<bool> structure;
  for (const StepSummary& st : s.per_step) structure.push_back(st.structure_changed);
  EXPECT_EQ(structure, (std::vector<bool>{false, false, true, false, true}));
  EXPECT_EQ(s.per_step[2].change,
            "+1/-0 tasks, +3/-1 edges, contacts +a|b, groups merged: {a} + {b}");
  EXPECT_EQ(s.per_step[4].change.rfind("+0/-1 tasks", 0), 0u) << s.per_step[4].change;
  EXPECT_TRUE(s.per_step[1].change.empty());
}

TEST(TraceSummary, JsonAndTextCarryTheFigures) {
  Trace t;
  t.header.scene = "two";
  t.header.engine = "test";
  t.steps = {step(false, 3, 1000), step(true, 5, 1000)};
  const TraceSummary s = summarize_trace(t);
  const nlohmann::json j = nlohmann::json::parse(trace_summary_json(s, "t.tgt"));
  EXPECT_EQ(j["trace"], "t.tgt");
  EXPECT_EQ(j["scene"], "two");
  EXPECT_EQ(j["steps"], 2);
  EXPECT_EQ(j["tasks"], s.tasks);
  EXPECT_EQ(j["tasks_per_step"]["max"], 5);
  EXPECT_EQ(j["work_ns"], s.work_ns);
  EXPECT_EQ(j["contact_changes"], 1);
  ASSERT_EQ(j["per_step"].size(), 2u);
  EXPECT_EQ(j["per_step"][1]["contacts_changed"], true);
  EXPECT_EQ(j["per_step"][1]["loop_iterations"], nlohmann::json::array({5}));
  ASSERT_EQ(j["structure_changes"].size(), 1u);
  EXPECT_EQ(j["structure_changes"][0]["step"], 1);
  EXPECT_EQ(j["structure_changes"][0]["summary"], s.per_step[1].change);
  const std::string text = trace_summary_text(s, "t.tgt");
  EXPECT_NE(text.find("trace          t.tgt (scene two, engine test)\n"), std::string::npos)
      << text;
  EXPECT_NE(text.find("steps          2\n"), std::string::npos);
  EXPECT_NE(
      text.find(
          "contacts       1 steps whose contact set changed; last step 1 collision group(s)\n"),
      std::string::npos);
}

TEST(TraceSummary, TotalsSayTheySumOverStepsAndGiveTheLongestStep) {
  Trace t;
  t.steps = {step(false, 3, 1000), step(false, 5, 1000)};
  const TraceSummary s = summarize_trace(t);
  EXPECT_EQ(s.span_ns, s.per_step[0].span_ns + s.per_step[1].span_ns);
  EXPECT_EQ(s.span_max_ns, std::max(s.per_step[0].span_ns, s.per_step[1].span_ns));
  EXPECT_FALSE(s.unit_cost);
  const nlohmann::json j = nlohmann::json::parse(trace_summary_json(s, "t.tgt"));
  EXPECT_EQ(j["span_max_ns"], s.span_max_ns);
  EXPECT_FALSE(j.contains("span_tasks"));
  const TraceSummary u = summarize_trace(t, {.unit_cost = true});
  EXPECT_TRUE(u.unit_cost);
  EXPECT_EQ(u.span_tasks, u.per_step[0].span_tasks + u.per_step[1].span_tasks);
  EXPECT_EQ(u.span_tasks_max, std::max(u.per_step[0].span_tasks, u.per_step[1].span_tasks));
  EXPECT_GT(u.span_tasks_max, 0u);
}

TEST(TraceSummary, UnitCostTraceGivesItsSpanInTasksNotZeroMilliseconds) {
  Trace t;
  t.steps = {step(false, 3, 1000)};
  for (Task& task : t.steps[0].tasks) task.cost_ns = 1;  // unit costs
  const TraceSummary s = summarize_trace(t);
  EXPECT_TRUE(s.unit_cost);  // on by itself: the timed span says nothing
  const std::string text = trace_summary_text(s, "u.tgt");
  EXPECT_EQ(text.find("0.000 ms"), std::string::npos) << text;
  EXPECT_NE(text.find("span (unit)    " + std::to_string(s.span_tasks) + " tasks"),
            std::string::npos)
      << text;
}

TEST(TraceSummary, OfAnEmptyTraceIsZero) {
  const TraceSummary s = summarize_trace(Trace{});
  EXPECT_EQ(s.steps, 0u);
  EXPECT_EQ(s.tasks_min, 0u);
  EXPECT_EQ(s.tasks_mean, 0.0);
  EXPECT_EQ(s.parallelism, 0.0);
  EXPECT_EQ(nlohmann::json::parse(trace_summary_json(s, "e.tgt"))["per_step"].size(), 0u);
}

// A capture beside a busy process: one task on a step's critical path interrupted (50x its
// cost). The raw parallelism of that step collapses; the robust one (each task's median
// over the steps of its structure) stays within 20 % of the quiet capture's.
TEST(TraceSummary, RobustCostsIgnoreAnInterruptedTaskOnTheCriticalPath) {
  GenerateOptions go;
  go.pattern = Pattern::kDomain;
  go.tasks = 200;
  go.iterations = 5;
  Trace quiet;
  for (std::uint32_t i = 0; i < 5; ++i) {
    quiet.steps.push_back(generate_step(go, i));
    quiet.steps.back().derive_edges();
  }
  Trace busy = quiet;
  StepGraph& g = busy.steps[2];
  const std::vector<std::uint64_t> ef = earliest_finish(g);
  const auto last = static_cast<TaskId>(std::max_element(ef.begin(), ef.end()) - ef.begin());
  g.tasks[last].cost_ns *= 50;
  const TraceSummary q = summarize_trace(quiet), b = summarize_trace(busy);
  const auto within = [](double x, double ref) { return std::abs(x - ref) <= 0.2 * ref; };
  EXPECT_FALSE(within(b.per_step[2].parallelism, q.per_step[2].parallelism))
      << b.per_step[2].parallelism << " vs " << q.per_step[2].parallelism;
  EXPECT_TRUE(within(b.per_step[2].robust_parallelism, q.per_step[2].robust_parallelism))
      << b.per_step[2].robust_parallelism << " vs " << q.per_step[2].robust_parallelism;
  EXPECT_TRUE(within(b.robust_parallelism, q.robust_parallelism));
  // Every step of one structure has the same robust costs: the median of each task's.
  const auto robust = robust_costs(busy.steps);
  for (std::size_t i = 1; i < robust.size(); ++i) EXPECT_EQ(robust[i], robust[0]);
  const nlohmann::json j = nlohmann::json::parse(trace_summary_json(b, "b.tgt"));
  EXPECT_DOUBLE_EQ(j["robust_parallelism"].get<double>(), b.robust_parallelism);
  EXPECT_TRUE(j["costs"].get<std::string>().find("median") != std::string::npos);
  EXPECT_NE(trace_summary_text(b, "b.tgt").find("robust"), std::string::npos);
}

TEST(TraceSummary, SaysHowManyEdgesAreLoopCarried) {
  Trace t;
  t.steps.push_back(step(false, 3, 10));
  const TraceSummary s = summarize_trace(t);
  EXPECT_EQ(s.edges_carried, t.steps[0].carried_edges.size());
  EXPECT_GT(s.edges_carried, 0u);
  EXPECT_EQ(s.edges, t.steps[0].edges.size() + t.steps[0].carried_edges.size());
  EXPECT_NE(trace_summary_text(s, "t.tgt").find("loop-carried"), std::string::npos);
  const nlohmann::json j = nlohmann::json::parse(trace_summary_json(s, "t.tgt"));
  EXPECT_EQ(j["edges_carried"], s.edges_carried);
}

}  // namespace
}  // namespace tgraph
