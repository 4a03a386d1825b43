// SPDX-License-Identifier: MIT
// The live run's repartition trigger (measure::RepartitionTrigger): noise in the measured
// costs of a static scene never triggers, a real drift triggers once, and the gain / cost
// rule is exact on a tiny graph.
#include "tgraph/measure/trigger.hpp"

#include <gtest/gtest.h>

#include <cstdint>
#include <random>
#include <vector>

#include "live_observers.hpp"
#include "tgraph/graph/step_graph.hpp"
#include "tgraph/measure/capture.hpp"
#include "tgraph/partition/strategy.hpp"

namespace tgraph::measure {
namespace {

// Two independent tasks of 1000 ns, one per processor.
StepGraph two_tasks() {
  StepGraph g;
  g.kinds = {"work"};
  g.objects = {{"a"}, {"b"}};
  g.data = {{"x", 0, 8}, {"y", 1, 8}};
  for (ObjectId o = 0; o < 2; ++o) {
    Task t;
    t.kind = 0;
    t.object = o;
    t.cost_ns = 1000;
    t.access_begin = static_cast<std::uint32_t>(g.accesses.size());
    t.access_count = 1;
    g.accesses.push_back({o, AccessMode::W});
    g.tasks.push_back(t);
  }
  g.derive_edges();
  return g;
}

TEST(RepartitionTrigger, FiresExactlyWhenTheGainOverTheHorizonExceedsTheCost) {
  StepGraph g = two_tasks();
  Assignment a;
  a.k = 2;
  a.proc = {0, 1};
  // 16 bytes of data over 2 processors at 1 ns a byte: 8 ns of migration.
  const TriggerOptions o{.tolerance = 0.05, .loop_share = 0.0, .horizon = 10, .per_byte_ns = 1.0};
  // Task 0 then costs 2000 ns: imbalance 2000 / 1500; gain (4/3 - 1) x 1500 ns x 10 steps.
  const double gain = (4.0 / 3.0 - 1.0) * 1500.0 * 10.0;
  const auto cost_just_below = static_cast<std::int64_t>(gain) - 8 - 1;
  for (const std::int64_t rebuild : {cost_just_below, cost_just_below + 2}) {
    RepartitionTrigger trigger(o);
    g.tasks[0].cost_ns = 1000;
    // The reference and its noise (none): kSettle observations, none can fire.
    for (std::uint32_t i = 0; i < RepartitionTrigger::kSettle; ++i)
      EXPECT_FALSE(trigger.observe(g, a, 0)) << i;
    EXPECT_DOUBLE_EQ(trigger.current(), 1.0);
    g.tasks[0].cost_ns = 2000;
    EXPECT_FALSE(trigger.observe(g, a, rebuild));  // a first drift is not enough
    EXPECT_DOUBLE_EQ(trigger.reference(), 1.0);
    EXPECT_EQ(trigger.observe(g, a, rebuild), rebuild == cost_just_below);  // the second
    EXPECT_DOUBLE_EQ(trigger.reference(), 1.0);
    EXPECT_NEAR(trigger.gain_ns(), gain, 1e-6);
    EXPECT_DOUBLE_EQ(trigger.cost_ns(), static_cast<double>(rebuild + 8));
  }
  // A drift within the tolerance never fires, whatever the cost.
  RepartitionTrigger quiet(o);
  g.tasks[0].cost_ns = 1000;
  for (std::uint32_t i = 0; i < RepartitionTrigger::kSettle; ++i) quiet.observe(g, a, 0);
  g.tasks[0].cost_ns = 1040;  // 1040 / 1020 = 1.0196
  for (int i = 0; i < 5; ++i) EXPECT_FALSE(quiet.observe(g, a, 0));
  // After reset() the observations start afresh: the drifted level is the new reference.
  g.tasks[0].cost_ns = 2000;
  quiet.reset();
  for (int i = 0; i < 6; ++i) EXPECT_FALSE(quiet.observe(g, a, 0));
  EXPECT_NEAR(quiet.reference(), 4.0 / 3.0, 1e-12);
  // A drift that does not pay (a rebuild dearer than the gain) becomes the reference.
  g.tasks[0].cost_ns = 4000;  // loads 4000 and 1000: 1.6
  EXPECT_FALSE(quiet.observe(g, a, 1'000'000'000));
  EXPECT_FALSE(quiet.observe(g, a, 1'000'000'000));
  // Folded into the reference and the noise: no longer drifts, even with nothing to pay.
  EXPECT_FALSE(quiet.observe(g, a, 0));
  EXPECT_FALSE(quiet.observe(g, a, 0));
}

// Noise makes the trigger wait: observations that swing by 30 % set a band no drift of the
// same size crosses.
TEST(RepartitionTrigger, NoisyObservationsWidenTheBand) {
  StepGraph g = two_tasks();
  Assignment a;
  a.k = 2;
  a.proc = {0, 1};
  RepartitionTrigger trigger({.loop_share = 0.0});
  for (const std::uint64_t c : {1000, 1600, 1000, 1600, 1000, 1600}) {
    g.tasks[0].cost_ns = c;
    EXPECT_FALSE(trigger.observe(g, a, 0));
  }
  g.tasks[0].cost_ns = 1700;  // 1700 / 1350 = 1.26, within the band of 3 sigma
  EXPECT_FALSE(trigger.observe(g, a, 0));
  EXPECT_FALSE(trigger.observe(g, a, 0));
}

// bars64's step, each task costing 1 ns per 8 bytes of the data it touches (at least
// 100 ns: deterministic, unlike the costs a capture on a busy machine measures), and owner's
// assignment at K = 16.
struct Bars {
  StepGraph g;
  std::vector<std::uint64_t> base;
  Assignment a;
};

const Bars& bars() {
  static const Bars b = [] {
    Bars r;
    r.g = capture_trace("bars64", 1).steps.at(0);
    for (TaskId t = 0; t < r.g.tasks.size(); ++t) {
      std::uint64_t bytes = 0;
      for (const Access& acc : r.g.accesses_of(t)) bytes += r.g.data[acc.datum].bytes;
      r.base.push_back(std::max<std::uint64_t>(bytes / 8, 100));
      r.g.tasks[t].cost_ns = r.base.back();
    }
    r.a = partition::make_strategy("owner")->partition(r.g, 16, {}, {}).assignment;
    return r;
  }();
  return b;
}

// Runs `steps` steps of measured costs: every task's cost is its base times `scale(task,
// step)` times independent noise uniform in [0.8, 1.2], smoothed as the live run smooths
// (detail::smoothed_cost); the trigger observes each step; when it fires the assignment is
// remade by `method` from the smoothed costs and the trigger reset, as the live run does.
// Returns the steps at which it fired.
template <class Scale>
std::vector<std::uint32_t> fires(const std::string& method, std::uint32_t steps,
                                 std::uint32_t seed, Scale scale) {
  const Bars& b = bars();
  StepGraph g = b.g;
  Assignment a = b.a;
  for (Task& t : g.tasks) t.cost_ns = 1;
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<double> noise(0.8, 1.2);
  // Rebuilding bars64's plans at 16 threads costs about 1 ms (tgraph run --json build_ns).
  constexpr std::int64_t kRebuildNs = 1'000'000;
  RepartitionTrigger trigger;
  auto strategy = partition::make_strategy(method);
  std::vector<std::uint32_t> at;
  for (std::uint32_t s = 0; s < steps; ++s) {
    for (TaskId t = 0; t < g.tasks.size(); ++t) {
      const double sample = static_cast<double>(b.base[t]) * scale(t, s) * noise(rng);
      g.tasks[t].cost_ns = detail::smoothed_cost(g.tasks[t].cost_ns,
                                                 static_cast<std::uint64_t>(sample));
    }
    if (trigger.observe(g, a, kRebuildNs)) {
      at.push_back(s);
      a = strategy->partition(g, 16, {&g, &a}, {}).assignment;
      trigger.reset();
    }
  }
  return at;
}

TEST(RepartitionTrigger, TwentyPercentNoiseOnEveryTaskOfBars64NeverFiresInFiftySteps) {
  for (std::uint32_t seed = 1; seed <= 10; ++seed)
    for (const char* method : {"owner", "sticky"}) {
      const auto at = fires(method, 50, seed, [](TaskId, std::uint32_t) { return 1.0; });
      EXPECT_TRUE(at.empty()) << method << ", seed " << seed << ": fired at step " << at.front();
    }
}

TEST(RepartitionTrigger, OneBarOfBars64TwiceAsCostlyFiresOnce) {
  const Bars& b = bars();
  const ObjectId bar = b.g.tasks.at(0).object;
  ASSERT_NE(bar, kNoObject);
  for (std::uint32_t seed = 1; seed <= 10; ++seed)
    for (const char* method : {"owner", "sticky"}) {
      const auto at = fires(method, 50, seed, [&](TaskId t, std::uint32_t s) {
        return s >= 20 && b.g.tasks[t].object == bar ? 2.0 : 1.0;
      });
      ASSERT_EQ(at.size(), 1u) << method << ", seed " << seed;
      EXPECT_GE(at[0], 20u);
      EXPECT_LE(at[0], 23u);
    }
}

}  // namespace
}  // namespace tgraph::measure
