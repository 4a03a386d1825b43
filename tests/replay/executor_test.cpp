// SPDX-License-Identifier: MIT
#include "tgraph/replay/executor.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <cstring>
#include <iterator>
#include <nlohmann/json.hpp>
#include <numeric>
#include <stdexcept>
#include <string>
#include <thread>

#include "random_graph.hpp"
#include "tgraph/graph/error.hpp"
#include "tgraph/replay/synthetic.hpp"

namespace tgraph::replay {
namespace {

using test::final_state;
using test::sequential_state;

struct Variant {
  Policy policy;
  bool serial;
  const char* name;
  BarrierRule rule = BarrierRule::kLevel;
};

const Variant kVariants[] = {
    {Policy::kPartition, false, "partition"},
    {Policy::kPartition, true, "partition_serial"},
    {Policy::kWorksteal, false, "worksteal"},
    {Policy::kBarrier, false, "barrier"},
    {Policy::kBarrier, false, "barrier_operation", BarrierRule::kOperation},
    {Policy::kBarrier, false, "barrier_omp_for", BarrierRule::kOmpFor},
    {Policy::kOmpTasks, false, "omp_tasks"},
};

ExecOptions opts(std::uint32_t k, bool serial = false, std::int64_t spin_ns = kDefaultSpinNs) {
  return test::partition_options(k, serial, spin_ns);
}

ExecOptions options_for(const Variant& v, std::uint32_t k) {
  ExecOptions o = test::partition_options(k, v.serial, 20'000);
  o.barrier.rule = v.rule;
  return o;
}

class EveryPolicy : public ::testing::TestWithParam<std::tuple<int, std::uint32_t>> {};

TEST_P(EveryPolicy, RunsEachTaskAfterItsPredecessorsAndMatchesSequentialState) {
  const auto [vi, k] = GetParam();
  const Variant& v = kVariants[vi];
  for (std::uint32_t seed = 1; seed <= 6; ++seed) {
    const StepGraph g = test::random_graph(seed * 7919 + k);
    const Assignment a = test::random_assignment(g, k, seed);
    auto ex = make_executor(v.policy, options_for(v, k));
    TimelineObserver timeline;
    ex->add_observer(timeline);
    SyntheticWorkload w({.cost_scale = 0.2});
    w.set_step(g);
    for (int step = 0; step < 2; ++step) {
      const ExecStepStats s = ex->run_step(g, &a, w);
      EXPECT_EQ(s.rebuilt, step == 0);
      for (LoopId l = 0; l < g.loops.size(); ++l)
        EXPECT_EQ(s.loop_iterations[l], g.loops[l].iterations);
      ASSERT_NE(ex->last_exec(), nullptr);
      test::expect_valid_order(ex->last_exec()->graph, timeline.timeline().tasks,
                               static_cast<std::uint32_t>(step), {.exec = true});
      test::expect_valid_order(g, timeline.timeline().tasks, static_cast<std::uint32_t>(step),
                               {.raw_only = true});
    }
    EXPECT_EQ(ex->plans_built(), 1u);
    const auto got = final_state(w, g), want = sequential_state(g, 2);
    for (DatumId d = 0; d < g.data.size(); ++d)
      EXPECT_TRUE(got[d] == want[d]) << v.name << " seed " << seed << " k " << k << ": datum "
                                     << g.data[d].name << " differs from the sequential run";
    if (::testing::Test::HasFailure()) return;
  }
}

INSTANTIATE_TEST_SUITE_P(Threads1To8, EveryPolicy,
                         ::testing::Combine(::testing::Range(0, static_cast<int>(std::size(kVariants))),
                                            ::testing::Range(1u, 9u)),
                         [](const auto& param_info) {
                           return std::string(kVariants[std::get<0>(param_info.param)].name) +
                                  "_k" + std::to_string(std::get<1>(param_info.param));
                         });

/// A graph where four tasks add into one datum, then one task reads it.
StepGraph cw_fan_in(int writers) {
  StepGraph g;
  g.intern_kind("add");
  g.intern_kind("read");
  g.objects.push_back({"o"});
  g.data.push_back({"f", 0, 8});
  g.data.push_back({"out", 0, 8});
  for (int i = 0; i < writers; ++i) {
    const Access acc[] = {{0, AccessMode::CW}};
    g.add_task(0, 0, acc, 100, static_cast<StableKey>(i + 1));
  }
  const Access acc[] = {{0, AccessMode::R}, {1, AccessMode::W}};
  g.add_task(1, 0, acc, 100, 99);
  g.derive_edges();
  return g;
}

/// Doubles: CW adds 0.1 * (task + 1) / 3, which depends on the summation order.
class DoubleWorkload : public Workload {
 public:
  void bind(const ExecGraph& x) override { v_.assign(x.graph.data.size(), 0.0); }
  void run(const TaskRun& r) override {
    const ExecGraph& x = *r.exec;
    if (r.origin == kNoTask) {
      const Reduction& red = x.reductions[x.reduction[r.task]];
      for (DatumId t : red.temps) {
        v_[red.target] += v_[t];
        v_[t] = 0.0;
      }
      return;
    }
    double in = 0;
    for (const Access& a : x.graph.accesses_of(r.task))
      if (reads(a.mode)) in += v_[a.datum];
    for (const Access& a : x.graph.accesses_of(r.task)) {
      if (a.mode == AccessMode::CW || a.mode == AccessMode::RW)
        v_[a.datum] += 0.1 * (r.origin + 1) / 3.0;
      if (a.mode == AccessMode::W) v_[a.datum] = in;
    }
  }
  bool stop_after(LoopId, std::uint32_t) override { return true; }
  double value(DatumId d) const { return v_[d]; }

 private:
  std::vector<double> v_;
};

TEST(CwReduction, CrossProcessorWritesGoThroughTemporariesAndOneReducer) {
  const StepGraph g = cw_fan_in(6);
  Assignment a;
  a.k = 3;
  a.proc = {0, 1, 2, 1, 2, 0, 0};
  const ExecGraph x = lower(g, &a, CwMode::kReduce);
  ASSERT_EQ(x.reductions.size(), 1u);
  EXPECT_EQ(x.reductions[0].target, 0u);
  ASSERT_EQ(x.reductions[0].temps.size(), 2u);  // processors 1 and 2
  EXPECT_EQ(x.graph.data[x.reductions[0].temps[0]].name, "f@1");
  EXPECT_EQ(x.graph.data[x.reductions[0].temps[1]].name, "f@2");
  EXPECT_EQ(x.graph.tasks.size(), g.tasks.size() + 1);
  const TaskId reducer = x.exec_of[5] + 1;
  EXPECT_EQ(x.origin[reducer], kNoTask);
  EXPECT_EQ(x.assignment.proc[reducer], 0u);
  // The reader depends on the reducer, and on no writer off the home processor.
  bool reader_after_reducer = false;
  for (const Edge& e : x.graph.edges) {
    if (e.to != x.exec_of[6]) continue;
    reader_after_reducer |= e.from == reducer;
    EXPECT_EQ(x.assignment.proc[e.from], 0u);
  }
  EXPECT_TRUE(reader_after_reducer);
  // On one processor nothing is lowered.
  Assignment one;
  one.k = 1;
  one.proc.assign(g.tasks.size(), 0);
  EXPECT_TRUE(lower(g, &one, CwMode::kReduce).reductions.empty());
}

TEST(CwReduction, IsDeterministicAcrossRunsAndEqualsTheSerialTwin) {
  const StepGraph g = cw_fan_in(12);
  Assignment a;
  a.k = 3;
  for (TaskId t = 0; t < g.tasks.size(); ++t) a.proc.push_back((t * 7) % 3);
  double expected = 0;
  {
    ExecOptions o = opts(3, true);
    auto ex = make_executor(Policy::kPartition, o);
    DoubleWorkload w;
    ex->run_step(g, &a, w);
    expected = w.value(0);
  }
  std::uint64_t expected_bits = 0;
  std::memcpy(&expected_bits, &expected, 8);
  auto ex = make_executor(Policy::kPartition, opts(3, false, 5'000));
  for (int run = 0; run < 30; ++run) {
    DoubleWorkload w;
    ex->run_step(g, &a, w);
    const double got = w.value(0);
    std::uint64_t bits = 0;
    std::memcpy(&bits, &got, 8);
    ASSERT_EQ(bits, expected_bits) << "run " << run;
  }
  double plain = 0;
  for (TaskId t = 0; t < 12; ++t) plain += 0.1 * (t + 1) / 3.0;
  EXPECT_NEAR(expected, plain, 1e-12);
}

// The dot product's reducer and scalar run on whichever processor finishes its partial sums
// last: here the one whose partial tasks take 2 ms each (the others' take nothing). Waiting
// threads park at once, so that three threads on fewer cores still let the fast ones arrive.
TEST(CombinedReductions, RunOnTheLastProcessorToArriveAndLeaveTheSequentialState) {
  constexpr std::uint32_t kIterations = 5;
  constexpr int kSteps = 3;
  for (std::uint32_t k : {2u, 3u}) {
    for (ProcId slow : {0u, 1u}) {
      const test::DotLoop d = test::dot_loop(6, k, kIterations, slow, 2'000'000);
      // Tasks per thread when every task runs on its own processor (the serial twin).
      std::vector<std::uint64_t> own(k, 0);
      {
        auto twin = make_executor(Policy::kPartition, opts(k, true));
        SyntheticWorkload w({.cost_scale = 0.0});
        w.set_step(d.g);
        const ExecStepStats s = twin->run_step(d.g, &d.a, w);
        for (ProcId p = 0; p < k; ++p) own[p] = s.threads[p].tasks;
      }
      for (bool combine : {true, false}) {
        ExecOptions o = opts(k, false, 0);
        o.partition.combine = combine;
        auto ex = make_executor(Policy::kPartition, o);
        SyntheticWorkload w({.cost_scale = 1.0});
        w.set_step(d.g);
        std::int64_t on_slow = 0;  // combined tasks the slow thread ran
        for (int step = 0; step < kSteps; ++step) {
          const ExecStepStats s = ex->run_step(d.g, &d.a, w);
          std::uint64_t total = 0;
          for (ProcId p = 0; p < k; ++p) total += s.threads[p].tasks;
          EXPECT_EQ(total, std::accumulate(own.begin(), own.end(), std::uint64_t{0}));
          if (!combine) {
            for (ProcId p = 0; p < k; ++p)
              EXPECT_EQ(s.threads[p].tasks, own[p]) << "k=" << k << " thread " << p;
            continue;
          }
          const auto extra = static_cast<std::int64_t>(s.threads[slow].tasks) -
                             static_cast<std::int64_t>(own[slow]);
          on_slow += slow == 0 ? 2 * kIterations + extra : extra;  // home: own holds them
        }
        // The reducer and the scalar, each iteration of each step, on the slow thread (80 %:
        // a fast thread preempted on a loaded machine may arrive last once in a while).
        // With more threads than cores, a fast thread sharing the slow one's core may well
        // arrive last: then only the results are compared.
        if (combine && k <= std::thread::hardware_concurrency()) {
          EXPECT_GE(on_slow, 2 * kIterations * kSteps * 8 / 10) << "k=" << k << " slow " << slow;
        }
        const auto got = final_state(w, d.g), want = sequential_state(d.g, kSteps);
        for (DatumId x = 0; x < d.g.data.size(); ++x)
          EXPECT_TRUE(got[x] == want[x]) << "k=" << k << " slow " << slow << " combine "
                                         << combine << ": datum " << d.g.data[x].name;
      }
    }
  }
}

using test::Throwing;

TEST(Executor, RethrowsATaskExceptionAfterJoiningAndStaysUsable) {
  const StepGraph g = test::random_graph(42);
  for (const Variant& v : kVariants) {
    for (std::uint32_t k : {1u, 2u, 4u}) {
      const Assignment a = test::random_assignment(g, k, 3);
      auto ex = make_executor(v.policy, options_for(v, k));
      for (TaskId bad : {TaskId{0}, static_cast<TaskId>(g.tasks.size() / 2), g.loops[0].last - 2}) {
        Throwing w(bad);
        try {
          ex->run_step(g, &a, w);
          ADD_FAILURE() << v.name << " k=" << k << ": no exception";
        } catch (const std::runtime_error& e) {
          EXPECT_EQ(std::string(e.what()), "task " + std::to_string(bad) + " failed") << v.name;
        }
      }
      SyntheticWorkload ok({.cost_scale = 0.0});
      ok.set_step(g);
      EXPECT_NO_THROW(ex->run_step(g, &a, ok)) << v.name << " k=" << k;
    }
  }
}

TEST(Executor, ReusesThePlanWhileTheStructureRepeats) {
  StepGraph g = test::random_graph(5);
  const Assignment a = test::random_assignment(g, 2, 1);
  auto ex = make_executor(Policy::kPartition, opts(2));
  SyntheticWorkload w({.cost_scale = 0.0});
  w.set_step(g);
  const ExecStepStats first = ex->run_step(g, &a, w);
  EXPECT_TRUE(first.rebuilt);
  EXPECT_GT(first.build_ns, 0);
  EXPECT_GE(first.wall_ns, first.build_ns);
  StepGraph g2 = g;  // new costs and iteration counts: same structure
  for (Task& t : g2.tasks) t.cost_ns += 7;
  g2.loops[0].iterations = 1;
  w.set_step(g2);
  const ExecStepStats second = ex->run_step(g2, &a, w);
  EXPECT_FALSE(second.rebuilt);
  EXPECT_EQ(second.build_ns, 0);
  EXPECT_EQ(second.loop_iterations[0], 1u);
  Assignment b = a;
  b.proc[0] = 1 - b.proc[0];
  EXPECT_TRUE(ex->run_step(g2, &b, w).rebuilt);
  EXPECT_FALSE(ex->run_step(g2, &a, w).rebuilt);  // still cached
  EXPECT_EQ(ex->plans_built(), 2u);
}

// The plan cache's key hashes the numbers of a structure, not its names: a step that differs
// only in a datum's or a kind's name shares the key and must still get its own plan (the
// exec graph it runs names its data in reports), and each of the two stays cached.
TEST(Executor, TellsApartStepsThatDifferOnlyInNames) {
  const StepGraph g = test::random_graph(5);
  const Assignment a = test::random_assignment(g, 2, 1);
  StepGraph renamed = g;
  renamed.data[0].name += "'";
  StepGraph rekinded = g;
  rekinded.kinds[0] += "'";
  for (Policy policy : {Policy::kSequential, Policy::kPartition}) {
    auto ex = make_executor(policy, opts(2));
    SyntheticWorkload w({.cost_scale = 0.0});
    w.set_step(g);
    EXPECT_TRUE(ex->run_step(g, &a, w).rebuilt);
    EXPECT_TRUE(ex->run_step(renamed, &a, w).rebuilt);
    EXPECT_TRUE(ex->run_step(rekinded, &a, w).rebuilt);
    EXPECT_FALSE(ex->run_step(g, &a, w).rebuilt);
    EXPECT_FALSE(ex->run_step(renamed, &a, w).rebuilt);
    EXPECT_EQ(ex->plans_built(), 3u);
    EXPECT_EQ(ex->last_exec()->graph.data[0].name, g.data[0].name + "'");
  }
}

TEST(Executor, RejectsBadAssignments) {
  const StepGraph g = test::random_graph(9);
  auto ex = make_executor(Policy::kPartition, opts(2));
  SyntheticWorkload w({.cost_scale = 0.0});
  w.set_step(g);
  EXPECT_THROW(ex->run_step(g, nullptr, w), UsageError);
  Assignment a = test::random_assignment(g, 3, 1);
  EXPECT_THROW(ex->run_step(g, &a, w), UsageError);  // k != threads
  a = test::random_assignment(g, 2, 1);
  a.proc.pop_back();
  EXPECT_THROW(ex->run_step(g, &a, w), UsageError);
  EXPECT_THROW(make_executor(Policy::kWorksteal, opts(0)), UsageError);
}

TEST(Executor, RejectsATaskOrderThatWouldDeadlock) {
  // t0 (p0) writes d0, t1 (p1) reads d0 and writes d1, t2 (p0) reads d1.
  StepGraph g;
  g.intern_kind("k");
  g.data = {{"d0", kNoObject, 8}, {"d1", kNoObject, 8}};
  const Access a0[] = {{0, AccessMode::W}};
  const Access a1[] = {{0, AccessMode::R}, {1, AccessMode::W}};
  const Access a2[] = {{1, AccessMode::R}};
  g.add_task(0, kNoObject, a0);
  g.add_task(0, kNoObject, a1);
  g.add_task(0, kNoObject, a2);
  g.derive_edges();
  Assignment a;
  a.k = 2;
  a.proc = {0, 1, 0};
  a.order = {{2, 0}, {1}};  // p0 runs t2 before t0: t2 waits for t1, t1 for t0
  auto ex = make_executor(Policy::kPartition, opts(2));
  SyntheticWorkload w;
  w.set_step(g);
  try {
    ex->run_step(g, &a, w);
    FAIL() << "no error";
  } catch (const UsageError& e) {
    EXPECT_NE(std::string(e.what()).find("deadlock"), std::string::npos) << e.what();
  }
  a.order = {{0, 2}, {1}};
  EXPECT_NO_THROW(ex->run_step(g, &a, w));
}

TEST(Locality, CountsRemoteReadsAndMigratedData) {
  StepGraph g;
  g.intern_kind("k");
  g.data = {{"d", kNoObject, 1000}};
  const Access w0[] = {{0, AccessMode::W}};
  const Access r1[] = {{0, AccessMode::R}};
  g.add_task(0, kNoObject, w0);
  g.add_task(0, kNoObject, r1);
  g.derive_edges();
  auto ex = make_executor(Policy::kPartition, opts(2, true));
  LocalityObserver loc;
  ex->add_observer(loc);
  SyntheticWorkload w({.cost_scale = 0.0});
  w.set_step(g);
  Assignment a{2, {0, 1}, {}};
  ex->run_step(g, &a, w);
  EXPECT_EQ(loc.remote_bytes(), 1000u);
  EXPECT_EQ(loc.migrated_bytes(), 0u);
  ex->run_step(g, &a, w);
  EXPECT_EQ(loc.migrated_bytes(), 0u);
  Assignment b{2, {1, 1}, {}};
  ex->run_step(g, &b, w);
  EXPECT_EQ(loc.remote_bytes(), 0u);
  EXPECT_EQ(loc.migrated_bytes(), 1000u);  // the writer moved from thread 0 to thread 1
}

TEST(Timeline, ExportsEveryTaskInstanceToJson) {
  const StepGraph g = test::random_graph(11);
  const Assignment a = test::random_assignment(g, 2, 2);
  auto ex = make_executor(Policy::kPartition, opts(2));
  TimelineObserver tl;
  ex->add_observer(tl);
  SyntheticWorkload w({.cost_scale = 0.0});
  w.set_step(g);
  ex->run_step(g, &a, w);
  std::size_t instances = 0;
  for (TaskId t = 0; t < g.tasks.size(); ++t) instances += g.runs(t);
  std::size_t original = 0;
  for (const TimelineTask& e : tl.timeline().tasks) original += e.origin.has_value() ? 1 : 0;
  EXPECT_EQ(original, instances);
  // One record per event, in the same order, with the kind of its exec task (viz reads this
  // file back: tests/viz/timeline_test.cpp).
  const nlohmann::json j = nlohmann::json::parse(timeline_json(tl.timeline()));
  EXPECT_EQ(j.at("threads"), 2u);
  EXPECT_EQ(j.at("steps"), 1u);
  ASSERT_EQ(j.at("tasks").size(), tl.timeline().tasks.size());
  ASSERT_EQ(j.at("waits").size(), tl.timeline().waits.size());
  for (std::size_t i = 0; i < tl.timeline().tasks.size(); ++i) {
    const TimelineTask& e = tl.timeline().tasks[i];
    const nlohmann::json& r = j["tasks"][i];
    EXPECT_EQ(r.at("thread"), e.thread);
    EXPECT_EQ(r.at("task"), e.task);
    EXPECT_EQ(r.at("kind"), e.kind);
    EXPECT_EQ(e.kind, ex->last_exec()->graph.kind_name(e.task));
    EXPECT_EQ(r.at("origin").is_null(), !e.origin);
    EXPECT_EQ(r.at("start_ns"), e.start_ns);
    EXPECT_EQ(r.at("end_ns"), e.end_ns);
  }
}

TEST(Synthetic, SpinsForTheRecordedCost) {
  StepGraph g;
  g.intern_kind("k");
  g.data = {{"d", kNoObject, 4096}};
  const Access acc[] = {{0, AccessMode::RW}};
  g.add_task(0, kNoObject, acc, 2'000'000);  // 2 ms
  g.derive_edges();
  auto ex = make_executor(Policy::kSequential, {});
  SyntheticWorkload w;
  w.set_step(g);
  std::vector<std::int64_t> walls;
  for (int i = 0; i < 5; ++i) walls.push_back(ex->run_step(g, nullptr, w).wall_ns);
  std::sort(walls.begin(), walls.end());
  // About 2 ms, not 2 µs: a spin rate calibrated while a loaded machine preempted the
  // calibration makes the body spin too few iterations (0.77 ms was seen at load 9 under
  // TSan), so the bound is a tenth of the cost, still 100 times a unit error's 2 µs.
  EXPECT_GT(walls[2], 200'000);
  EXPECT_LT(walls[0], 200'000'000);  // not a unit error either
  EXPECT_GT(SyntheticWorkload::calibration().spin_iterations_per_ns, 0.0);
}

// Blocked waits are timed with the time-stamp counter, converted to nanoseconds by a factor
// measured once: a reader on thread 1 waiting for a 20 ms writer on thread 0 reports about
// 20 ms of waiting, never more than the step's wall time.
// Every blocked wait parks at once (spin 0): each hand-off goes through the sleep/wake
// protocol (sync.hpp: with two threads on two cores, the asymmetric fence, the signaller only
// storing), many times per step. A lost wake-up would stall a step: the watchdog turns it
// into an error here instead of a hang. The states still match the sequential run's.
TEST(Executor, WaitsThatAllParkAreAllWoken) {
  for (std::uint32_t seed = 1; seed <= 3; ++seed) {
    const StepGraph g = test::random_graph(seed * 104729);
    const Assignment a = test::random_assignment(g, 2, seed);
    ExecOptions o = opts(2, false, 0);
    o.partition.timeout_ms = 20'000;
    auto ex = make_executor(Policy::kPartition, o);
    SyntheticWorkload w({.cost_scale = 0.0});
    w.set_step(g);
    std::uint64_t parks = 0;
    for (int step = 0; step < 300; ++step) {
      ExecStepStats s;
      ASSERT_NO_THROW(s = ex->run_step(g, &a, w)) << "seed " << seed << " step " << step;
      parks += s.parks();
      for (LoopId l = 0; l < g.loops.size(); ++l)
        ASSERT_EQ(s.loop_iterations[l], g.loops[l].iterations);
    }
    EXPECT_GT(parks, 0u) << "seed " << seed;
    const auto got = final_state(w, g), want = sequential_state(g, 300);
    for (DatumId d = 0; d < g.data.size(); ++d)
      EXPECT_TRUE(got[d] == want[d]) << "seed " << seed << ": datum " << g.data[d].name;
  }
}

TEST(Executor, TimesBlockedWaitsInNanoseconds) {
  StepGraph g;
  g.intern_kind("write");
  g.intern_kind("read");
  g.data = {{"x", kNoObject, 8}};
  const Access w_acc[] = {{0, AccessMode::W}};
  const Access r_acc[] = {{0, AccessMode::R}};
  g.add_task(0, kNoObject, w_acc, 20'000'000, 1);
  g.add_task(1, kNoObject, r_acc, 0, 2);
  g.derive_edges();
  const Assignment a{2, {0, 1}, {}};
  ExecOptions o = opts(2);
  o.spin_ns = 1'000'000;  // spins 1 ms, then parks: both halves of a wait are timed
  o.partition.steal = false;  // thread 1 would otherwise take the write while it waits
  auto ex = make_executor(Policy::kPartition, o);
  SyntheticWorkload w({.cost_scale = 1.0, .touch = false});
  w.set_step(g);
  ex->run_step(g, &a, w);  // the first step also waits for the buffers' first touch
  const ExecStepStats s = ex->run_step(g, &a, w);
  ASSERT_EQ(s.threads.size(), 2u);
  EXPECT_EQ(s.threads[1].blocked_waits, 1u);
  // The reader waits for most of the step (the write is its only work) and past the spin
  // budget (it parked). Against the step's own wall time, not the nominal 20 ms: the
  // synthetic spin's rate is measured once per process, and under ctest -j 2 beside another
  // busy test it once came out slow enough that the write spun 7 ms.
  EXPECT_GE(s.threads[1].wait_ns, s.wall_ns / 2);
  EXPECT_GE(s.threads[1].wait_ns, 2 * o.spin_ns);
  EXPECT_LE(s.threads[1].wait_ns, s.wall_ns);
  EXPECT_EQ(s.threads[0].wait_ns, 0);
}

}  // namespace
}  // namespace tgraph::replay
