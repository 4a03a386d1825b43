// SPDX-License-Identifier: MIT
// Evaluation numbers on hand-made traces.
#include <gtest/gtest.h>

#include <nlohmann/json.hpp>

#include "test_graphs.hpp"
#include "tgraph/graph/error.hpp"
#include "tgraph/partition/evaluate.hpp"
#include "tgraph/partition/strategy.hpp"

namespace tgraph::partition {
namespace {

using testing::Builder;
using testing::M;

TraceAssignment one_step(std::uint32_t k, std::vector<ProcId> proc) {
  TraceAssignment a;
  a.method = "hand";
  a.k = k;
  Assignment s;
  s.k = k;
  s.proc = std::move(proc);
  a.steps = {s};
  a.partition_ms = {2.5};
  return a;
}

// Four tasks of 10 ns: 0 writes x (100 bytes); 1 and 2 read x and reduce into f (40 bytes);
// 3 reads f. The tests put 0, 1 and 3 on p0 and 2 on p1.
StepGraph writer_two_reducers_reader() {
  Builder b;
  const DatumId x = b.datum("x", 100), f = b.datum("f", 40);
  b.task({{x, M::W}}, 10);              // 0
  b.task({{x, M::R}, {f, M::CW}}, 10);  // 1
  b.task({{x, M::R}, {f, M::CW}}, 10);  // 2
  b.task({{f, M::R}}, 10);              // 3
  return b.done();
}

TEST(Evaluate, CountsCutSignalsReducersAndImbalance) {
  Trace tr;
  tr.steps = {writer_two_reducers_reader()};
  const Report r = evaluate(tr, one_step(2, {0, 0, 1, 0}), model::CostModel::ideal());
  const StepReport& s = r.steps[0];
  // Cross edges: 0->2 (x, 100 bytes) and 2->3 (f, 40 bytes).
  EXPECT_EQ(s.cut_edges, 2u);
  EXPECT_EQ(s.cut_bytes, 140u);
  EXPECT_EQ(s.signals, 2u);
  EXPECT_EQ(s.waits, 2u);
  EXPECT_EQ(s.reducers, 1u);
  EXPECT_DOUBLE_EQ(s.imbalance, 1.5);  // loads 30 and 10
  EXPECT_EQ(s.work_ns, 40u);
  EXPECT_EQ(s.span_ns, 30u);
  EXPECT_EQ(s.lower_bound_ns, 30u);
  EXPECT_EQ(s.makespan_ns, 30u);
  EXPECT_DOUBLE_EQ(s.speedup, 40.0 / 30.0);
  EXPECT_DOUBLE_EQ(s.partition_ms, 2.5);
  // p0 -> p1 (x) and p1 -> p0 (f): the two processors wait on each other within the step.
  EXPECT_FALSE(s.quotient_acyclic);
  EXPECT_EQ(s.ping_pong_pairs, 1u);
  EXPECT_EQ(r.total.cut_bytes, 140u);
  EXPECT_EQ(r.model, "ideal");
}

TEST(Evaluate, ReportJsonAndTextCarryTheTotals) {
  Builder b;
  const DatumId x = b.datum("x", 100), f = b.datum("f", 40);
  b.task({{x, M::W}}, 10);
  b.task({{x, M::R}, {f, M::CW}}, 10);
  b.task({{x, M::R}, {f, M::CW}}, 10);
  b.task({{f, M::R}}, 10);
  Trace tr;
  tr.steps = {b.done()};
  const Report r = evaluate(tr, one_step(2, {0, 0, 1, 0}), model::CostModel::ideal());
  const nlohmann::json j = nlohmann::json::parse(report_json(r));
  EXPECT_EQ(j["method"], "hand");
  EXPECT_EQ(j["k"], 2);
  EXPECT_EQ(j["model"], "ideal");
  EXPECT_EQ(j["cut_bytes"], 140);
  EXPECT_EQ(j["predicted_makespan_ns"], 30);
  EXPECT_EQ(j["quotient_acyclic"], false);
  ASSERT_EQ(j["per_step"].size(), 1u);
  EXPECT_EQ(j["per_step"][0]["reducers"], 1);
  EXPECT_FALSE(nlohmann::json::parse(report_json(r, false)).contains("per_step"));
  EXPECT_EQ(report_text(r),
            "method hand, k = 2, 1 steps, cost model: ideal\n"
            "  cut: 2 edges, 140 bytes; 2 signals, 2 waits, 1 reducers, " +
                std::to_string(r.total.transfer_bytes) +
                " bytes moved\n"
                "  imbalance 1.500 (worst step 1.500); migrations: 0 tasks, 0 bytes\n"
                "  predicted makespan 0.000 ms, lower bound 0.000 ms, work 0.000 ms: speed-up 1.33 "
                "(0.00 with 2.500 ms partitioning)\n"
                "  robust costs (each task's the median of its key over the steps of its "
                "structure): imbalance 1.500, predicted makespan 0.000 ms, speed-up 1.33\n"
                "  quotient graph: cyclic (1 steps with cycles, 1 ping-pong pairs)\n");
}

// One task interrupted in one of three steps of one structure (1,000 ns instead of 10): the
// raw prediction of that step carries it, the robust one (the median of the task's key over
// the three) does not.
TEST(Evaluate, RobustFiguresIgnoreOneInterruptedTask) {
  Trace tr;
  tr.steps = {writer_two_reducers_reader(), writer_two_reducers_reader(),
              writer_two_reducers_reader()};
  tr.steps[1].tasks[3].cost_ns = 1000;
  TraceAssignment a = one_step(2, {0, 0, 1, 0});
  a.steps = {a.steps[0], a.steps[0], a.steps[0]};
  a.partition_ms = {0, 0, 0};
  const Report r = evaluate(tr, a, model::CostModel::ideal());
  EXPECT_EQ(r.steps[1].makespan_ns, 1020u);
  EXPECT_DOUBLE_EQ(r.steps[1].imbalance, 1020.0 * 2 / 1030.0);
  for (const StepReport& s : r.steps) {
    EXPECT_EQ(s.robust_makespan_ns, 30u);
    EXPECT_EQ(s.robust_work_ns, 40u);
    EXPECT_DOUBLE_EQ(s.robust_imbalance, 1.5);
    EXPECT_DOUBLE_EQ(s.robust_speedup, 40.0 / 30.0);
  }
  EXPECT_EQ(r.total.makespan_ns, 1080u);
  EXPECT_EQ(r.total.robust_makespan_ns, 90u);
  EXPECT_DOUBLE_EQ(r.total.robust_imbalance, 1.5);
  const nlohmann::json j = nlohmann::json::parse(report_json(r));
  EXPECT_EQ(j["robust_predicted_makespan_ns"], 90);
  EXPECT_EQ(j["per_step"][1]["predicted_makespan_ns"], 1020);
  EXPECT_EQ(j["per_step"][1]["robust_predicted_makespan_ns"], 30);
  EXPECT_TRUE(j["costs"].get<std::string>().starts_with("raw: the recorded costs; robust_*"));
}

TEST(Evaluate, ReportsPingPongBetweenProcessorsAsACycle) {
  Builder b;
  const DatumId x = b.datum("x", 8), y = b.datum("y", 8);
  b.task({{x, M::W}}, 1);                // p0
  b.task({{x, M::R}, {y, M::W}}, 1);     // p1
  b.task({{y, M::R}}, 1);                // p0
  Trace tr;
  tr.steps = {b.done()};
  const Report r = evaluate(tr, one_step(2, {0, 1, 0}), model::CostModel::defaults());
  EXPECT_FALSE(r.steps[0].quotient_acyclic);
  EXPECT_EQ(r.steps[0].ping_pong_pairs, 1u);
  EXPECT_EQ(r.cyclic_steps, 1u);
}

TEST(Evaluate, CountsMigrationsByStableKey) {
  Builder b;
  const DatumId x = b.datum("x", 100), y = b.datum("y", 30);
  b.g.add_task(0, kNoObject, std::vector<Access>{{x, M::RW}}, 5, 1);
  b.g.add_task(0, kNoObject, std::vector<Access>{{y, M::RW}, {x, M::R}}, 5, 2);
  const StepGraph g0 = b.done();
  // Next step: a new task first, then the two old ones (matched by key, not by index).
  Builder c;
  c.datum("x", 100);
  c.datum("y", 30);
  c.g.add_task(0, kNoObject, std::vector<Access>{{y, M::R}}, 5, 3);
  c.g.add_task(0, kNoObject, std::vector<Access>{{x, M::RW}}, 5, 1);
  c.g.add_task(0, kNoObject, std::vector<Access>{{y, M::RW}, {x, M::R}}, 5, 2);
  Trace tr;
  tr.steps = {g0, c.done()};
  TraceAssignment a = one_step(2, {0, 1});
  Assignment s1;
  s1.k = 2;
  s1.proc = {1, 0, 0};  // key 2 moved from p1 to p0; key 1 stayed on p0
  a.steps.push_back(s1);
  a.partition_ms.push_back(0.5);
  const Report r = evaluate(tr, a, model::CostModel::ideal());
  EXPECT_EQ(r.steps[0].migrated_tasks, 0u);
  EXPECT_EQ(r.steps[1].migrated_tasks, 1u);
  EXPECT_EQ(r.steps[1].migrated_bytes, 130u);
  EXPECT_EQ(r.total.migrated_tasks, 1u);
  EXPECT_DOUBLE_EQ(r.total.partition_ms, 3.0);
}

TEST(Evaluate, RejectsAnAssignmentThatDoesNotFitTheTrace) {
  Trace tr;
  tr.steps = {testing::two_halves(3)};
  EXPECT_THROW(evaluate(tr, one_step(2, {0, 1, 0}), model::CostModel::ideal(), "a.tga"),
               InputError);
  try {
    evaluate(tr, one_step(2, {0, 1, 0, 1, 0}), model::CostModel::ideal(), "a.tga");
    FAIL();
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("a.tga: step 0: assignment covers 5 tasks, the step has 6"), std::string::npos)
        << e.what();
  }
  TraceAssignment two = one_step(2, {0, 1, 0, 1, 0, 1});
  two.steps.push_back(two.steps[0]);
  EXPECT_THROW(evaluate(tr, two, model::CostModel::ideal(), "a.tga"), InputError);
  TraceAssignment deadlock = one_step(1, {0, 0, 0, 0, 0, 0});
  deadlock.steps[0].order = {{1, 0, 2, 3, 4, 5}};
  EXPECT_THROW(evaluate(tr, deadlock, model::CostModel::ideal(), "a.tga"), InputError);
}

TEST(Evaluate, EvaluatesATracePartitionedByEveryMethod) {
  Trace tr;
  for (std::uint64_t s = 0; s < 4; ++s) tr.steps.push_back(testing::random_graph(40 + s, 60, 8, true));
  for (const std::string& m : strategy_names()) {
    const TracePartition tp = partition_trace(tr, m, 4);
    ASSERT_EQ(tp.assignment.steps.size(), 4u);
    const Report ideal = evaluate(tr, tp.assignment, model::CostModel::ideal());
    EXPECT_GE(ideal.total.makespan_ns, ideal.total.lower_bound_ns) << m;
    EXPECT_GE(ideal.total.imbalance, 1.0) << m;
    EXPECT_GT(ideal.total.speedup, 0.0) << m;
  }
}

TEST(StepQuotient, SplitsTheCutAndTheSignalsByProcessorPair) {
  const StepGraph g = writer_two_reducers_reader();
  const QuotientGraph q = step_quotient(g, Assignment{2, {0, 0, 1, 0}, {}});
  EXPECT_EQ(q.load_ns, (std::vector<std::uint64_t>{30, 10}));
  ASSERT_EQ(q.edges.size(), 2u);
  EXPECT_EQ(q.edges[0], (QuotientEdge{0, 1, 1, 0, 100, 1}));  // x, one version sent
  EXPECT_EQ(q.edges[1], (QuotientEdge{1, 0, 1, 0, 40, 1}));   // f
  EXPECT_THROW(step_quotient(g, Assignment{2, {0, 0, 1}, {}}), Error);
}

// A loop whose break runs on p0 while p1 runs part of its body: p1 waits for the decision of
// every iteration, an edge of signals without dependencies.
TEST(StepQuotient, CountsLoopDecisionsAsSignals) {
  Builder b;
  const DatumId y = b.datum("y", 8), cond = b.datum("cond", 1);
  b.task({{y, M::RW}}, 3);    // 0 p1
  b.task({{cond, M::W}}, 1);  // 1 p0
  b.task({{cond, M::R}}, 1);  // 2 p0, the break
  b.loop(cond, 0, 3, 4);
  const QuotientGraph q = step_quotient(b.done(), Assignment{2, {1, 0, 0}, {}});
  ASSERT_EQ(q.edges.size(), 1u);
  EXPECT_EQ(q.edges[0], (QuotientEdge{0, 1, 0, 0, 0, 4}));
}

// On random graphs with loops, summed over the pairs: evaluate's cut, the simulator's waits.
TEST(StepQuotient, SumsToEvaluatesCutAndWaitsOnRandomGraphs) {
  for (std::uint64_t seed = 0; seed < 20; ++seed) {
    Trace tr;
    tr.steps = {testing::random_graph(seed, 40, 6, true)};
    TraceAssignment a = one_step(3, {});
    for (TaskId t = 0; t < tr.steps[0].tasks.size(); ++t)
      a.steps[0].proc.push_back(static_cast<ProcId>((t * 7 + seed) % 3));
    const StepReport r = evaluate(tr, a, model::CostModel::ideal()).steps[0];
    const QuotientGraph q = step_quotient(tr.steps[0], a.steps[0]);
    std::uint64_t deps = 0, bytes = 0, signals = 0, work = 0;
    for (const QuotientEdge& e : q.edges) {
      EXPECT_NE(e.from, e.to);
      deps += e.deps + e.carried_deps;
      bytes += e.bytes;
      signals += e.signals;
    }
    for (std::uint64_t l : q.load_ns) work += l;
    EXPECT_EQ(deps, r.cut_edges) << seed;
    EXPECT_EQ(bytes, r.cut_bytes) << seed;
    EXPECT_EQ(signals, r.waits) << seed;
    EXPECT_EQ(work, r.work_ns) << seed;
  }
}

}  // namespace
}  // namespace tgraph::partition
