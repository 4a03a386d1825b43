// SPDX-License-Identifier: MIT
// The capture API: tasks, loops, stable keys, deferred mode.
#include "tgraph/capture/recorder.hpp"

#include <gtest/gtest.h>

#include <array>
#include <cstddef>
#include <cstring>
#include <functional>
#include <ranges>
#include <span>
#include <vector>

namespace tgraph::capture {
namespace {

using M = AccessMode;

// Busy-waits (a task body that costs `d` of wall time).
void busy_wait(std::chrono::nanoseconds d) {
  const auto until = std::chrono::steady_clock::now() + d;
  while (std::chrono::steady_clock::now() < until) {
  }
}

// One step holding one loop on datum "c" whose break never fires, so that it runs
// `iterations` times (its maximum); each iteration records one task writing c that runs `body`.
StepGraph loop_of_one_task(Recorder& rec, std::uint32_t iterations, const std::function<void()>& body) {
  const DatumId c = rec.datum("c", kNoObject, 1);
  const KindId k = rec.kind("k");
  rec.begin_step();
  const LoopId l = rec.begin_loop(c, iterations);
  do {
    rec.task(k, kNoObject, {{c, M::W}}, [&body] { body(); });
  } while (!rec.conditional_break(l, [] { return false; }));
  rec.end_loop(l);
  return rec.end_step();
}

struct Scene {
  Recorder rec;
  double x = 0, v = 1, f = 0, res = 1;
  ObjectId obj;
  DatumId dx, dv, df, dres;
  KindId force, integrate, solve;
  explicit Scene(Mode mode) : rec(mode) {
    obj = rec.object("ball");
    dx = rec.datum("ball.x", obj, 8, &x);
    dv = rec.datum("ball.v", obj, 8, &v);
    df = rec.datum("ball.f", obj, 8, &f);
    dres = rec.datum("res", kNoObject, 8, &res);
    force = rec.kind("addForce");
    integrate = rec.kind("integrate");
    solve = rec.kind("solve");
  }
  // One step: force, a loop halving res until below 0.1 (4 iterations from 1), integrate.
  void step() {
    rec.begin_step();
    rec.task(force, obj, {{dx, M::R}, {df, M::W}}, [this] { f = -x; });
    res = 1;
    const LoopId l = rec.begin_loop(dres, 50);
    do {
      rec.task(solve, obj, {{dres, M::RW}}, [this] { res *= 0.5; });
    } while (!rec.conditional_break(l, [this] { return res < 0.1; }));
    rec.end_loop(l);
    rec.task(integrate, obj, {{df, M::R}, {dv, M::RW}, {dx, M::RW}}, [this] {
      v += f * 0.1;
      x += v * 0.1;
    });
  }
};

TEST(Recorder, CapturesTasksLoopsAndIterations) {
  Scene s(Mode::kCapture);
  s.step();
  const StepGraph g = s.rec.end_step();
  EXPECT_EQ(s.rec.errors(), 0u);
  ASSERT_EQ(g.validate(), "");
  ASSERT_EQ(g.tasks.size(), 4u);  // force, solve, loop.break, integrate
  EXPECT_EQ(g.kind_name(2), "loop.break");
  ASSERT_EQ(g.loops.size(), 1u);
  EXPECT_EQ(g.loops[0].iterations, 4u);  // 0.5, 0.25, 0.125, 0.0625
  EXPECT_EQ(g.loops[0].first, 1u);
  EXPECT_EQ(g.loops[0].last, 3u);
  EXPECT_EQ(g.runs(1), 4u);
  EXPECT_EQ(g.runs(3), 1u);
  EXPECT_DOUBLE_EQ(s.res, 0.0625);   // the bodies really ran 4 times
  EXPECT_DOUBLE_EQ(s.x, 0.1);        // and the integrate task once
  // force -> integrate (f, RAW); x read by force then rewritten by integrate (WAR).
  EXPECT_NE(std::find(g.edges.begin(), g.edges.end(), Edge{0, 3, s.df, EdgeKind::RAW}), g.edges.end());
  EXPECT_NE(std::find(g.edges.begin(), g.edges.end(), Edge{0, 3, s.dx, EdgeKind::WAR}), g.edges.end());
}

// Read accesses made on the fly from data ids, as `ids | std::views::transform(...)` makes
// them (written by hand: clang 14, the asan preset's compiler, cannot compile libstdc++ 12's
// views): a non-contiguous range whose elements are Access values, not references.
struct ReadsOf {
  const std::vector<DatumId>& ids;
  struct iterator {
    using value_type = Access;
    using difference_type = std::ptrdiff_t;
    std::vector<DatumId>::const_iterator at;
    Access operator*() const { return Access{*at, AccessMode::R}; }
    iterator& operator++() {
      ++at;
      return *this;
    }
    iterator operator++(int) { return {at++}; }
    bool operator==(const iterator&) const = default;
  };
  iterator begin() const { return {ids.begin()}; }
  iterator end() const { return {ids.end()}; }
};
static_assert(std::ranges::input_range<ReadsOf> && !std::ranges::contiguous_range<ReadsOf>);

TEST(Recorder, AccessesGivenAsAnyRangeRecordTheSameGraphAsAnInitializerList) {
  // The same three tasks issued with an initializer list, then with a vector, an array, a
  // span and a range of values made on the fly (non-contiguous: copied by the recorder).
  const auto run = [](int form) {
    Recorder rec(Mode::kCapture);
    const ObjectId o = rec.object("o");
    const DatumId a = rec.datum("a", o, 8), b = rec.datum("b", o, 8), c = rec.datum("c", o, 8);
    const KindId k = rec.kind("k");
    int ran = 0;
    rec.begin_step();
    const std::vector<Access> first = {{a, M::W}};
    const std::array<Access, 2> second = {Access{a, M::R}, Access{b, M::CW}};
    const std::vector<DatumId> readers = {a, b};
    switch (form) {
      case 0:
        rec.task(k, o, {{a, M::W}}, [&] { ++ran; });
        rec.task(k, o, {{a, M::R}, {b, M::CW}}, [&] { ++ran; });
        rec.task(k, o, {{a, M::R}, {b, M::R}}, [&] { ++ran; });
        break;
      default:
        rec.task(k, o, first, [&] { ++ran; });
        rec.task(k, o, std::span<const Access>(second), [&] { ++ran; });
        rec.task(k, o, ReadsOf{readers}, [&] { ++ran; });
        break;
    }
    rec.task(k, o, std::vector<Access>{{c, M::W}, {a, M::R}}, [&] { ++ran; });
    StepGraph g = rec.end_step();
    EXPECT_EQ(ran, 4);
    EXPECT_EQ(rec.errors(), 0u);
    for (Task& t : g.tasks) t.cost_ns = 0;  // measured times differ between the runs
    return g;
  };
  const StepGraph listed = run(0), ranged = run(1);
  ASSERT_EQ(listed.tasks.size(), 4u);
  EXPECT_EQ(ranged.accesses, listed.accesses);
  EXPECT_EQ(ranged.edges, listed.edges);
  EXPECT_TRUE(ranged.same_structure(listed));
  EXPECT_EQ(ranged.accesses_of(2)[1], (Access{1, M::R}));
}

TEST(Recorder, StableKeysRepeatAcrossStepsAndStructureIsEqual) {
  Scene s(Mode::kCapture);
  s.step();
  const StepGraph a = s.rec.end_step();
  s.step();
  const StepGraph b = s.rec.end_step();
  ASSERT_EQ(a.tasks.size(), b.tasks.size());
  for (std::size_t t = 0; t < a.tasks.size(); ++t) EXPECT_EQ(a.tasks[t].key, b.tasks[t].key);
  EXPECT_NE(a.tasks[0].key, a.tasks[3].key);
  EXPECT_TRUE(a.same_structure(b));
  EXPECT_EQ(a.structural_hash(), b.structural_hash());
}

TEST(Recorder, KeepsTheHostTimeGivenToBeginStepForThatStepOnly) {
  Recorder rec(Mode::kCapture);
  const KindId k = rec.kind("k");
  const ObjectId o = rec.object("o");
  const DatumId x = rec.datum("x", o, 8);
  rec.begin_step(1234);
  rec.task(k, o, {{x, AccessMode::RW}}, [] {});
  EXPECT_EQ(rec.end_step().host_ns, 1234u);
  rec.begin_step();
  rec.task(k, o, {{x, AccessMode::RW}}, [] {});
  const StepGraph g = rec.end_step();
  EXPECT_EQ(g.host_ns, 0u);
  EXPECT_EQ(g.tasks.size(), 1u);
}

TEST(Recorder, OffModeRunsBodiesAndRecordsNothing) {
  Scene s(Mode::kOff);
  s.step();
  const StepGraph g = s.rec.end_step();
  EXPECT_TRUE(g.tasks.empty());
  EXPECT_DOUBLE_EQ(s.res, 0.0625);
  EXPECT_DOUBLE_EQ(s.x, 0.1);
}

TEST(Recorder, DeferredModeKeepsBodiesAndRunsNothing) {
  Scene s(Mode::kDeferred);
  s.step();
  StepProgram p = s.rec.end_step_program();
  EXPECT_DOUBLE_EQ(s.x, 0.0);  // nothing ran
  ASSERT_EQ(p.graph.tasks.size(), 4u);
  ASSERT_EQ(p.bodies.size(), 4u);
  ASSERT_EQ(p.conditions.size(), 1u);
  EXPECT_FALSE(static_cast<bool>(p.bodies[2]));  // the break task: run conditions[0]
  // Run it by hand in program order: body until the condition holds.
  p.bodies[0]();
  int iterations = 0;
  do {
    p.bodies[1]();
    ++iterations;
  } while (!p.conditions[0]());
  p.bodies[3]();
  EXPECT_EQ(iterations, 4);
  EXPECT_DOUBLE_EQ(s.x, 0.1);
}

TEST(Recorder, LoopStopsAtMaxIterations) {
  Recorder rec(Mode::kCapture);
  int n = 0;
  const StepGraph g = loop_of_one_task(rec, 7, [&] { ++n; });
  EXPECT_EQ(n, 7);
  EXPECT_EQ(g.loops[0].iterations, 7u);
}

TEST(Recorder, BodyChangingBetweenIterationsIsCountedAsError) {
  Recorder rec(Mode::kCapture);
  const DatumId c = rec.datum("c", kNoObject, 1);
  const KindId k = rec.kind("k");
  rec.begin_step();
  const LoopId l = rec.begin_loop(c, 3);
  int it = 0;
  do {
    rec.task(k, kNoObject, {{c, M::W}}, [] {});
    if (it++ == 1) rec.task(k, kNoObject, {{c, M::W}}, [] {});  // extra task in iteration 2
  } while (!rec.conditional_break(l, [] { return false; }));
  rec.end_loop(l);
  rec.end_step();
  EXPECT_GT(rec.errors(), 0u);
}

TEST(Recorder, ScopeRecordsOneTimedTask) {
  Recorder rec(Mode::kCapture);
  const DatumId d = rec.datum("d", kNoObject, 8);
  const KindId k = rec.kind("scoped");
  rec.begin_step();
  {
    Recorder::Scope s(rec, k, kNoObject, {{d, M::W}});
    volatile double acc = 0;
    for (int i = 0; i < 100000; ++i) acc = acc + i;
  }
  const StepGraph g = rec.end_step();
  ASSERT_EQ(g.tasks.size(), 1u);
  EXPECT_GT(g.tasks[0].cost_ns, 0u);
}

TEST(Recorder, LoopTaskCostLeavesOutItsLongestIteration) {
  Recorder rec(Mode::kCapture);
  int it = 0;
  const StepGraph g = loop_of_one_task(rec, 5, [&] {
    if (it++ == 2) busy_wait(std::chrono::milliseconds(20));  // one iteration "preempted" for 20 ms
  });
  ASSERT_EQ(g.loops[0].iterations, 5u);
  // With the outlier the mean would be >= 4 ms; without it, the empty body's cost.
  EXPECT_LT(g.tasks[0].cost_ns, 1'000'000u);
}

TEST(Recorder, TaskCostsAreInNanoseconds) {
  Recorder rec(Mode::kCapture);
  const DatumId c = rec.datum("c", kNoObject, 1);
  const KindId k = rec.kind("k");
  rec.begin_step();
  rec.task(k, kNoObject, {{c, AccessMode::W}}, [] {
    busy_wait(std::chrono::milliseconds(5));
  });
  const StepGraph g = rec.end_step();
  EXPECT_GE(g.tasks[0].cost_ns, 4'900'000u);
  EXPECT_LT(g.tasks[0].cost_ns, 2'000'000'000u);  // not µs, not ps: a loaded machine may stretch it
}

TEST(Recorder, SampledLoopTimingEstimatesThePerIterationCost) {
  Recorder rec(Mode::kCapture);
  int runs = 0;
  const StepGraph g = loop_of_one_task(rec, 20, [&] {
    ++runs;
    busy_wait(std::chrono::microseconds(200));
  });
  EXPECT_EQ(runs, 20);  // every iteration ran, timed or not
  ASSERT_EQ(g.loops[0].iterations, 20u);
  // Timed: iterations 0, 1, 2, 4, 8, 12, 16; each cost at least 200 us.
  EXPECT_GE(g.tasks[0].cost_ns, 200'000u);
  EXPECT_LT(g.tasks[0].cost_ns, 2'000'000u);
}

// Cost passes: the ball scene's state after every step equals a run with one pass, bit for
// bit (the written data are restored between passes), and bodies run `passes` times.
TEST(Recorder, CostPassesLeaveTheStateOfOneRunBitForBit) {
  Scene once(Mode::kCapture), five(Mode::kCapture);
  five.rec.set_cost_passes(5);
  EXPECT_EQ(five.rec.cost_passes(), 5u);
  for (int s = 0; s < 4; ++s) {
    once.step();
    const StepGraph a = once.rec.end_step();
    five.step();
    const StepGraph b = five.rec.end_step();
    EXPECT_TRUE(a.same_structure(b));
    EXPECT_EQ(a.loops[0].iterations, b.loops[0].iterations);
    EXPECT_EQ(std::memcmp(&once.x, &five.x, sizeof(double)), 0) << "step " << s;
    EXPECT_EQ(std::memcmp(&once.v, &five.v, sizeof(double)), 0) << "step " << s;
    EXPECT_EQ(std::memcmp(&once.res, &five.res, sizeof(double)), 0) << "step " << s;
  }
  EXPECT_EQ(five.rec.single_pass_runs(), 0u);
  EXPECT_EQ(five.rec.errors(), 0u);
}

TEST(Recorder, CostPassesKeepTheMedianSoOnePreemptedRunDoesNotSetTheCost) {
  Recorder rec(Mode::kCapture);
  double y = 0;
  const DatumId d = rec.datum("y", kNoObject, sizeof y, &y);
  const KindId k = rec.kind("k");
  rec.set_cost_passes(3);
  rec.begin_step();
  int runs = 0;
  rec.task(k, kNoObject, {{d, AccessMode::RW}}, [&] {
    y += 1.0;
    if (runs++ == 0) busy_wait(std::chrono::milliseconds(30));  // the "preempted" pass
  });
  const StepGraph g = rec.end_step();
  EXPECT_EQ(runs, 3);
  EXPECT_EQ(y, 1.0);  // restored before passes 2 and 3: one run's effect
  EXPECT_LT(g.tasks[0].cost_ns, 15'000'000u);
}

TEST(Recorder, TasksWritingDataWithoutStorageAreTimedOnceAndCounted) {
  Recorder rec(Mode::kCapture);
  const DatumId d = rec.datum("opaque", kNoObject, 8);  // no pointer: cannot be restored
  const KindId k = rec.kind("k");
  rec.set_cost_passes(4);
  rec.begin_step();
  int runs = 0;
  rec.task(k, kNoObject, {{d, AccessMode::W}}, [&] { ++runs; });
  rec.task(k, kNoObject, {{d, AccessMode::R}}, [&] { ++runs; });  // reads only: repeated
  rec.end_step();
  EXPECT_EQ(runs, 1 + 4);
  EXPECT_EQ(rec.single_pass_runs(), 1u);
}

}  // namespace
}  // namespace tgraph::capture
