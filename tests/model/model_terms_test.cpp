// SPDX-License-Identifier: MIT
// The simulator's machine terms (issue 39) on tiny graphs, each term's effect on the makespan
// computed by hand; the calibration file's new keys and older files without them.
#include <gtest/gtest.h>

#include <cstdio>
#include <fstream>
#include <nlohmann/json.hpp>
#include <string>

#include "test_graphs.hpp"
#include "test_model.hpp"
#include "tgraph/graph/error.hpp"
#include "tgraph/model/cost_model.hpp"
#include "tgraph/model/simulator.hpp"

namespace tgraph::model {
namespace {

using namespace tgraph::partition;  // the strategies that place the tasks

using model::testing::link_model;
using partition::testing::assign;
using partition::testing::Builder;
using partition::testing::M;

// t0 (cost 1000) writes x; t1 (cost 100) reads it.
StepGraph producer_consumer() {
  Builder b;
  const DatumId x = b.datum("x", 8);
  b.task({{x, M::W}}, 1000);
  b.task({{x, M::R}}, 100);
  return b.done();
}

// Two tasks of cost 1000 on disjoint data.
StepGraph two_independent() {
  Builder b;
  const DatumId x = b.datum("x", 8), y = b.datum("y", 8);
  b.task({{x, M::W}}, 1000);
  b.task({{y, M::W}}, 1000);
  return b.done();
}

TEST(ModelTerms, AWaitPastTheSpinBudgetAddsTheWakeUp) {
  CostModel m = link_model(10);
  m.spin_budget_ns = 200;
  // Without the term: p1 waits 0 -> 1010 and starts at 1000 + 10.
  const Schedule spin = simulate(producer_consumer(), assign(2, {0, 1}), m);
  EXPECT_EQ(spin.start_ns[1], 1010u);
  EXPECT_EQ(spin.makespan_ns, 1110u);
  // With it: that wait (1010 ns) outlasts the 200 ns budget, so p1 has parked and the
  // hand-off is the wake-up, 500 ns instead of 10: the makespan grows by exactly 490.
  m.park_wake_ns = 500;
  const Schedule parked = simulate(producer_consumer(), assign(2, {0, 1}), m);
  EXPECT_EQ(parked.start_ns[1], 1500u);
  EXPECT_EQ(parked.makespan_ns, spin.makespan_ns + 490u);
  // A wait within the budget spins: the latency again.
  m.spin_budget_ns = 2000;
  EXPECT_EQ(simulate(producer_consumer(), assign(2, {0, 1}), m).start_ns[1], 1010u);
  // On one processor nobody waits.
  m.spin_budget_ns = 200;
  EXPECT_EQ(simulate(producer_consumer(), assign(1, {0, 0}), m).makespan_ns, 1100u);
}

TEST(ModelTerms, InflationTwoAtTwoBusyProcessorsDoublesABody) {
  CostModel m = link_model(10);
  m.inflation = {{1, 1.0}, {2, 2.0}};
  // Both bodies run at once on two processors: each takes 2 x 1000.
  const Schedule both = simulate(two_independent(), assign(2, {0, 1}), m);
  EXPECT_EQ(both.end_ns, (std::vector<std::uint64_t>{2000, 2000}));
  EXPECT_EQ(both.makespan_ns, 2000u);
  // The same two on one processor of two: one busy at a time, no slow-down.
  const Schedule alone = simulate(two_independent(), assign(2, {0, 0}), m);
  EXPECT_EQ(alone.end_ns, (std::vector<std::uint64_t>{1000, 2000}));
  // Without the curve the parallel pair takes 1000.
  m.inflation.clear();
  EXPECT_EQ(simulate(two_independent(), assign(2, {0, 1}), m).makespan_ns, 1000u);
}

// Two tasks of cost 1000 on disjoint data of 1000 bytes each.
StepGraph two_independent_of_1000_bytes() {
  Builder b;
  const DatumId x = b.datum("x", 1000), y = b.datum("y", 1000);
  b.task({{x, M::W}}, 1000);
  b.task({{y, M::W}}, 1000);
  return b.done();
}

TEST(ModelTerms, InflationScalesATasksMemoryShareByTheMemoryCurveAndTheRestByTheComputeCurve) {
  CostModel m = link_model(0);
  m.inflation = {{1, 1.0}, {2, 2.0}};
  m.compute_inflation = {{1, 1.0}, {2, 1.0}};
  // 1000 bytes at 0.5 ns/byte: half of each 1000 ns body is memory, doubled; the other
  // half computes at full speed: 500 x 2 + 500 = 1500.
  m.inflation_ns_per_byte = 0.5;
  EXPECT_EQ(simulate(two_independent_of_1000_bytes(), assign(2, {0, 1}), m).end_ns,
            (std::vector<std::uint64_t>{1500, 1500}));
  EXPECT_DOUBLE_EQ(m.task_inflation(2, 1000, 1000), 1.5);
  // At 2 ns/byte the memory pass would outlast the body: all of it is memory, doubled.
  m.inflation_ns_per_byte = 2.0;
  EXPECT_EQ(simulate(two_independent_of_1000_bytes(), assign(2, {0, 1}), m).makespan_ns, 2000u);
  // A compute curve alone: the rest slowed by 1.2, the memory share not at all.
  m.inflation.clear();
  m.compute_inflation = {{2, 1.2}};
  m.inflation_ns_per_byte = 0.5;
  EXPECT_EQ(simulate(two_independent_of_1000_bytes(), assign(2, {0, 1}), m).makespan_ns, 1100u);
  // Without a time per byte (an older file), the memory curve scales the whole body.
  m.inflation = {{1, 1.0}, {2, 2.0}};
  m.inflation_ns_per_byte = 0;
  EXPECT_EQ(simulate(two_independent_of_1000_bytes(), assign(2, {0, 1}), m).makespan_ns, 2000u);
  EXPECT_DOUBLE_EQ(m.task_inflation(2, 1000, 1000), 2.0);
  // One busy processor at a time: no slow-down from either curve.
  m.inflation_ns_per_byte = 0.5;
  EXPECT_EQ(simulate(two_independent_of_1000_bytes(), assign(2, {0, 0}), m).makespan_ns, 2000u);
}

TEST(ModelTerms, InflationScalesABodyByTheMeanBusyCountDuringIt) {
  // t0 (1000) on p0 beside t1 (500) on p1: t1 always has two busy, t0 half its time.
  Builder b;
  const DatumId x = b.datum("x", 8), y = b.datum("y", 8);
  b.task({{x, M::W}}, 1000);
  b.task({{y, M::W}}, 500);
  CostModel m = link_model(0);
  m.inflation = {{1, 1.0}, {2, 2.0}};
  const Schedule s = simulate(b.done(), assign(2, {0, 1}), m);
  // Mean busy 1.5 -> factor 1.5 for t0; 2 -> factor 2 for t1.
  EXPECT_EQ(s.end_ns, (std::vector<std::uint64_t>{1500, 1000}));
}

TEST(ModelTerms, InflationCurveInterpolatesAndHoldsItsLastPoint) {
  CostModel m;
  EXPECT_DOUBLE_EQ(m.inflation_at(8), 1.0);  // no curve: no slow-down
  m.inflation = {{1, 1.0}, {2, 1.2}, {4, 1.6}};
  EXPECT_DOUBLE_EQ(m.inflation_at(1), 1.0);
  EXPECT_DOUBLE_EQ(m.inflation_at(1.5), 1.1);
  EXPECT_DOUBLE_EQ(m.inflation_at(3), 1.4);
  EXPECT_DOUBLE_EQ(m.inflation_at(16), 1.6);
  m.inflation = {{2, 1.5}};  // from (1, 1) to the first point
  EXPECT_DOUBLE_EQ(m.inflation_at(1.5), 1.25);
}

TEST(ModelTerms, TheExecutorsTimePerTaskIsChargedAtItsProcessorCountOnly) {
  CostModel m = link_model(10);
  m.executor_overhead = {{2, 40}, {4, 100}};
  // Two processors: each instance takes its cost plus 40 ns.
  const Schedule two = simulate(two_independent(), assign(2, {0, 1}), m);
  EXPECT_EQ(two.end_ns, (std::vector<std::uint64_t>{1040, 1040}));
  // The same tasks on one processor of a 2-processor assignment: still that executor.
  EXPECT_EQ(simulate(two_independent(), assign(2, {0, 0}), m).makespan_ns, 2080u);
  // One processor: the sequential engine, no executor.
  EXPECT_EQ(simulate(two_independent(), assign(1, {0, 0}), m).makespan_ns, 2000u);
  // Four: 100 ns each, on top of the runtime's own task_overhead_ns.
  m.task_overhead_ns = 5;
  EXPECT_EQ(simulate(two_independent(), assign(4, {0, 1}), m).makespan_ns, 1105u);
  // The curve: 0 at one thread, linear from there to its first point and between points,
  // its last beyond it.
  EXPECT_DOUBLE_EQ(m.executor_overhead_at(1), 0.0);
  EXPECT_DOUBLE_EQ(m.executor_overhead_at(3), 70.0);
  EXPECT_DOUBLE_EQ(m.executor_overhead_at(16), 100.0);
  m.executor_overhead = {{4, 90}};
  EXPECT_DOUBLE_EQ(m.executor_overhead_at(2), 30.0);
  m.executor_overhead.clear();
  EXPECT_DOUBLE_EQ(m.executor_overhead_at(8), 0.0);
}

// One task of `cost` ns.
StepGraph one_task(std::uint64_t cost) {
  Builder b;
  const DatumId x = b.datum("x", 8);
  b.task({{x, M::W}}, cost);
  return b.done();
}

TEST(ModelTerms, InterruptionsTakeTheirShareOfAProcessorsTimeInGapsOfTheMeasuredLengths) {
  CostModel m = link_model(10);
  // One thread busy: 5 % of its time lost in gaps of 50 us.
  m.interruptions = {{1, {{0.05, {50'000}}}}};
  // A 1 s body is lengthened by whole gaps, about lost / (1 - lost) of it: 52.6 ms (the
  // count of gaps is random, seeded: about 1,050 of them, within a tenth of that).
  const Schedule s = simulate(one_task(1'000'000'000), assign(1, {0}), m);
  const std::uint64_t added = s.makespan_ns - 1'000'000'000;
  EXPECT_EQ(added % 50'000, 0u);
  EXPECT_NEAR(static_cast<double>(added), 1e9 * 0.05 / 0.95, 1e9 * 0.05 / 0.95 / 10);
  // The same graph, the same schedule.
  EXPECT_EQ(simulate(one_task(1'000'000'000), assign(1, {0}), m).makespan_ns, s.makespan_ns);
  // The gaps fall on the processor's time, not on a task: 1000 tasks of 1 ms lose as much.
  Builder b;
  const DatumId x = b.datum("x", 8);
  for (int i = 0; i < 1000; ++i) b.task({{x, M::RW}}, 1'000'000);
  const Schedule chain = simulate(b.done(), assign(1, std::vector<ProcId>(1000, 0)), m);
  EXPECT_EQ((chain.makespan_ns - 1'000'000'000) % 50'000, 0u);
  EXPECT_NEAR(static_cast<double>(chain.makespan_ns - 1'000'000'000), 1e9 * 0.05 / 0.95,
              1e9 * 0.05 / 0.95 / 10);
  // No lost time, or no lengths: no gaps.
  m.interruptions = {{1, {{0.0, {50'000}}}}};
  EXPECT_EQ(simulate(one_task(1'000'000'000), assign(1, {0}), m).makespan_ns, 1'000'000'000u);
  m.interruptions = {{1, {{0.05, {}}}}};
  EXPECT_EQ(simulate(one_task(1'000'000'000), assign(1, {0}), m).makespan_ns, 1'000'000'000u);
}

TEST(ModelTerms, AnInterruptedProcessorStallsTheOneThatWaitsForIt) {
  CostModel m = link_model(10);
  // At two busy threads only the second CPU is interrupted.
  m.interruptions = {{1, {{0.0, {}}}}, {2, {{0.0, {}}, {0.1, {20'000, 40'000}}}}};
  // A 100 ms producer on p1 and its consumer on p0: the consumer starts when the
  // interrupted producer ends (its gaps of 20 or 40 us included), plus the latency.
  Builder b;
  const DatumId x = b.datum("x", 8);
  b.task({{x, M::W}}, 100'000'000);
  b.task({{x, M::R}}, 100);
  const Schedule s = simulate(b.done(), assign(2, {1, 0}), m);
  const std::uint64_t added = s.end_ns[0] - 100'000'000;
  EXPECT_EQ(added % 20'000, 0u);
  EXPECT_NEAR(static_cast<double>(added), 1e8 * 0.1 / 0.9, 1e8 * 0.1 / 0.9 / 5);
  EXPECT_EQ(s.start_ns[1], s.end_ns[0] + 10);
  EXPECT_EQ(s.busy_ns[1], 100'000'000 + added);
  // A clock around the body sees the gaps inside it; its kind's cost is the task's alone.
  EXPECT_EQ(s.body_ns[1], 100'000'000 + added);
  EXPECT_EQ(s.kind_body_ns[0], 100'000'000u + 100u);
  EXPECT_EQ(s.body_ns[0], 100u);
  // The other way round, the producer runs uninterrupted on p0.
  EXPECT_EQ(simulate(b.done(), assign(2, {0, 1}), m).end_ns[0], 100'000'000u);
}

TEST(ModelTerms, InterruptionsAtKBusyProcessorsComeFromTheMostThreadsMeasuredUpToK) {
  CostModel m;
  EXPECT_EQ(m.interruptions_at(2, 0), nullptr);
  m.interruptions = {{1, {{0.01, {6000}}}},
                     {2, {{0.02, {7000}}, {0.03, {8000}}}},
                     {4, {{0.04, {9000}}, {0.0, {9000}}}}};
  EXPECT_DOUBLE_EQ(m.interruptions_at(1, 0)->lost, 0.01);
  EXPECT_DOUBLE_EQ(m.interruptions_at(2, 1)->lost, 0.03);
  // Three threads: the two-thread point, its CPUs in turn.
  EXPECT_DOUBLE_EQ(m.interruptions_at(3, 2)->lost, 0.02);
  EXPECT_DOUBLE_EQ(m.interruptions_at(16, 0)->lost, 0.04);
  EXPECT_EQ(m.interruptions_at(16, 1), nullptr);  // nothing lost there
  m.interruptions = {{2, {{0.02, {7000}}}}};
  EXPECT_DOUBLE_EQ(m.interruptions_at(1, 0)->lost, 0.02);  // below the first: the first
}

TEST(ModelTerms, GivenSerialWorkRunsBeforeTheTasksAndWakesTheOthers) {
  CostModel m = link_model(10);
  m.spin_budget_ns = 200;
  m.park_wake_ns = 50;
  // 300 ns of the main thread's work (past the budget): p0 starts at 300, p1 is woken 50
  // later.
  const Schedule s = simulate(two_independent(), assign(2, {0, 1}), m, 300);
  EXPECT_EQ(s.start_ns, (std::vector<std::uint64_t>{300, 350}));
  EXPECT_EQ(s.makespan_ns, 1350u);
  // 100 ns (within the budget): both at 100.
  EXPECT_EQ(simulate(two_independent(), assign(2, {0, 1}), m, 100).start_ns,
            (std::vector<std::uint64_t>{100, 100}));
  // Given serial work replaces the host time.
  StepGraph g = two_independent();
  g.host_ns = 5000;
  EXPECT_EQ(simulate(g, assign(2, {0, 1}), m, 100).makespan_ns, 1100u);
  EXPECT_EQ(simulate(g, assign(2, {0, 1}), link_model(10)).makespan_ns, 6000u);
}

TEST(ModelTerms, NamesTheTermsAPredictionCharges) {
  CostModel m = link_model(10);
  EXPECT_EQ(model_terms(m, false, false), (std::vector<std::string>{"sync_latency", "per_byte"}));
  m.park_wake_ns = 5000;
  m.inflation = {{1, 1.0}, {2, 1.1}};
  m.task_overhead_ns = 3;
  m.executor_overhead = {{2, 150}};
  EXPECT_EQ(
      model_terms(m, true, true),
      (std::vector<std::string>{"sync_latency", "per_byte", "task_overhead", "executor_overhead",
                                "park_wake", "inflation", "serial_main_thread"}));
  m.compute_inflation = {{1, 1.0}, {2, 1.01}};
  m.inflation_ns_per_byte = 0.05;
  EXPECT_EQ(
      model_terms(m, false, false),
      (std::vector<std::string>{"sync_latency", "per_byte", "task_overhead", "executor_overhead",
                                "park_wake", "inflation", "compute_inflation", "memory_share"}));
  EXPECT_EQ(model_terms(CostModel::ideal(), false, true), (std::vector<std::string>{"host_time"}));
  m = link_model(10);
  m.interruptions = {{1, {{0.02, {7000}}}}};
  EXPECT_EQ(model_terms(m, false, false),
            (std::vector<std::string>{"sync_latency", "per_byte", "interruptions"}));
}

TEST(CalibrationFile, OlderFileWithoutTheNewKeysPredictsAsBefore) {
  const CostModel old =
      parse_calibration(R"({"sync_latency_ns": 80, "per_byte_ns": 0.04, "cpus": [0, 1]})", "old");
  EXPECT_DOUBLE_EQ(old.sync_latency_ns, 80);
  EXPECT_DOUBLE_EQ(old.park_wake_ns, 0);
  EXPECT_TRUE(old.inflation.empty());
  EXPECT_TRUE(old.reduction.empty());
  EXPECT_EQ(model_terms(old, false, false), (std::vector<std::string>{"sync_latency", "per_byte"}));
  // The long wait of producer_consumer costs the spin latency only.
  EXPECT_EQ(simulate(producer_consumer(), assign(2, {0, 1}), old).start_ns[1], 1080u);
}

TEST(CalibrationFile, NewKeysRoundTripThroughTheFile) {
  Calibration c;
  c.sync_latency_ns = 70;
  c.per_byte_ns = 0.03;
  c.park_wake_ns = 6500;
  c.inflation = {{1, 1.0}, {2, 1.08}};
  c.reduction = {{2, 180}};
  c.executor_overhead = {{2, 150.5}};
  c.executor_overhead_spread = {{2, {120, 150.5, 230}}};
  c.compute_inflation = {{1, 1.0}, {2, 1.01}};
  c.inflation_ns_per_byte = 0.045;
  c.interruptions = {{1, {{0.03, {5200, 48000}}}}, {2, {{0.025, {5100}}, {0.04, {6000, 90000}}}}};
  const std::string text = calibration_json(c);
  const nlohmann::json j = nlohmann::json::parse(text);
  EXPECT_DOUBLE_EQ(j.at("spin_handoff_ns").get<double>(), 70);
  EXPECT_DOUBLE_EQ(j.at("park_wake_ns").get<double>(), 6500);
  EXPECT_DOUBLE_EQ(j.at("inflation").at(1).at("factor").get<double>(), 1.08);
  EXPECT_EQ(j.at("inflation").at(1).at("threads").get<int>(), 2);
  EXPECT_DOUBLE_EQ(j.at("executor_overhead").at(0).at("ns").get<double>(), 150.5);
  EXPECT_DOUBLE_EQ(j.at("spread").at("executor_overhead").at(0).at("max").get<double>(), 230);
  const CostModel m = parse_calibration(text, "new");
  EXPECT_DOUBLE_EQ(m.sync_latency_ns, 70);
  EXPECT_DOUBLE_EQ(m.park_wake_ns, 6500);
  EXPECT_EQ(m.inflation, c.inflation);
  EXPECT_EQ(m.reduction, c.reduction);
  EXPECT_EQ(m.executor_overhead, c.executor_overhead);
  EXPECT_EQ(m.compute_inflation, c.compute_inflation);
  EXPECT_DOUBLE_EQ(m.inflation_ns_per_byte, 0.045);
  EXPECT_DOUBLE_EQ(j.at("interruptions").at(1).at("cpus").at(1).at("lost").get<double>(), 0.04);
  EXPECT_EQ(m.interruptions, c.interruptions);
  // Without it (partition's own measurement, an older file): no key, no term.
  c.executor_overhead.clear();
  c.executor_overhead_spread.clear();
  EXPECT_FALSE(nlohmann::json::parse(calibration_json(c)).contains("executor_overhead"));
  EXPECT_TRUE(parse_calibration(calibration_json(c), "old").executor_overhead.empty());
}

TEST(CalibrationFile, RejectsACurveThatIsNotOne) {
  for (const char* bad :
       {R"("inflation": 3)", R"("inflation": [{"threads": 2}])",
        R"("inflation": [{"threads": 2, "factor": 1.1}, {"threads": 1, "factor": 1}])",
        R"("inflation": [{"threads": 0, "factor": 1}])",
        R"("inflation": [{"threads": 2, "factor": -1}])",
        R"("executor_overhead": [{"threads": 2, "factor": 1}])",
        R"("executor_overhead": [{"threads": 2, "ns": -5}])",
        R"("interruptions": [{"threads": 1}])",
        R"("interruptions": [{"threads": 1, "cpus": [{"lost": 0.7, "lengths_ns": []}]}])",
        R"("interruptions": [{"threads": 1, "cpus": [{"lost": 0.1, "lengths_ns": [-1]}]}])",
        R"("interruptions": [{"threads": 2, "cpus": []}, {"threads": 2, "cpus": []}])"}) {
    const std::string text =
        std::string(R"({"sync_latency_ns": 80, "per_byte_ns": 0.04, )") + bad + "}";
    try {
      parse_calibration(text, "cal.json");
      ADD_FAILURE() << "accepted " << text;
    } catch (const InputError& e) {
      EXPECT_NE(std::string(e.what()).find("cal.json"), std::string::npos) << e.what();
      const std::string key = std::string(bad).substr(0, std::string(bad).find(':'));
      EXPECT_NE(std::string(e.what()).find(key), std::string::npos) << e.what();
    }
  }
}

TEST(SerialWork, ReadsRecordPartitionAndPrepareOfALiveRunPerStep) {
  const std::string path = ::testing::TempDir() + "tgraph_live_run.json";
  {
    std::ofstream f(path);
    f << R"({"per_step": [{"record_ns": 10, "partition_ns": 20, "prepare_ns": 3},
                          {"record_ns": 1, "partition_ns": 0, "prepare_ns": 2}]})";
  }
  EXPECT_EQ(load_serial_work(path), (std::vector<std::uint64_t>{33, 3}));
  // Per step of a trace: the first steps of the run, or one value for every step.
  EXPECT_EQ(serial_work(path, std::nullopt, 1), (std::vector<std::uint64_t>{33}));
  EXPECT_EQ(serial_work("", 5, 3), (std::vector<std::uint64_t>{5, 5, 5}));
  EXPECT_EQ(serial_work("", std::nullopt, 3), (std::vector<std::uint64_t>{}));
  try {
    serial_work(path, std::nullopt, 3);
    ADD_FAILURE() << "a run of 2 steps for a trace of 3";
  } catch (const OptionError& e) {
    EXPECT_EQ(std::string(e.what()), "live: " + path + ": the run has 2 steps, the trace 3");
  }
  {
    std::ofstream f(path);
    f << R"({"per_step": [{"record_ns": 10}]})";
  }
  EXPECT_THROW(load_serial_work(path), InputError);
  std::remove(path.c_str());
}

}  // namespace
}  // namespace tgraph::model
