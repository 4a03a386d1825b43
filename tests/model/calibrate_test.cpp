// SPDX-License-Identifier: MIT
// measure_calibration (`tgraph calibrate`): what it reports when the machine cannot be measured.
#include <gtest/gtest.h>
#include <pthread.h>
#include <sched.h>

#include <algorithm>
#include <nlohmann/json.hpp>
#include <stdexcept>
#include <string>
#include <thread>

#include "../quick_calibration.hpp"
#include "tgraph/graph/error.hpp"
#include "tgraph/model/cost_model.hpp"

namespace tgraph::model {
namespace {

// On one CPU there is nothing to measure: a failure of the work (exit 1 on the command
// line), not a tgraph::Error about the input (exit 2).
TEST(Calibration, OnOneCpuFailsAsTheWorkNotAsBadInput) {
  bool pinned = false, input_error = false, runtime_error = false;
  std::string what;
  std::thread t([&] {
    cpu_set_t one;
    CPU_ZERO(&one);
    CPU_SET(sched_getcpu(), &one);
    pinned = pthread_setaffinity_np(pthread_self(), sizeof one, &one) == 0;
    try {
      measure_calibration({.rounds = 500});
    } catch (const Error&) {
      input_error = true;
    } catch (const std::runtime_error& e) {
      runtime_error = true;
      what = e.what();
    }
  });
  t.join();
  ASSERT_TRUE(pinned);
  EXPECT_FALSE(input_error);
  EXPECT_TRUE(runtime_error);
  EXPECT_EQ(what, "calibrate: needs two CPUs, this process may use 1");
}

TEST(Spread, IsTheSamplesMinMedianAndMax) {
  EXPECT_EQ(spread_of({3.0, 1.0, 2.0}), (Spread{1.0, 2.0, 3.0}));
  EXPECT_EQ(spread_of({5.0, 1.0, 4.0, 2.0}), (Spread{1.0, 4.0, 5.0}));  // the upper median
  EXPECT_EQ(spread_of({}), Spread{});
}

// Each figure is the median of its samples, reported with their spread; the inflation is
// the measured median floored at 1; the file reads back with the same values.
TEST(Calibration, ReportsTheMedianOfItsSamplesAndTheirSpread) {
  const Calibration c = measure_calibration(tgraph::testing::quick_calibration());
  EXPECT_EQ(c.samples, 3);
  for (const auto& [spread, value] : {std::pair{c.latency_spread, c.sync_latency_ns},
                                      std::pair{c.park_wake_spread, c.park_wake_ns},
                                      std::pair{c.per_byte_spread, c.per_byte_ns}}) {
    EXPECT_EQ(spread.median, value);
    EXPECT_LE(spread.min, spread.median);
    EXPECT_LE(spread.median, spread.max);
  }
  EXPECT_GT(c.park_wake_spread.min, 0.0);
  ASSERT_GE(c.inflation.size(), 2u);
  ASSERT_EQ(c.inflation_spread.size(), c.inflation.size() - 1);  // K = 1 has no samples
  ASSERT_EQ(c.reduction_spread.size(), c.reduction.size());
  for (std::size_t i = 0; i < c.inflation_spread.size(); ++i) {
    const Spread& s = c.inflation_spread[i].spread;
    EXPECT_EQ(c.inflation_spread[i].threads, c.inflation[i + 1].threads);
    EXPECT_EQ(c.inflation[i + 1].value, std::max(1.0, s.median));
    EXPECT_LE(s.min, s.median);
    EXPECT_LE(s.median, s.max);
    EXPECT_EQ(c.reduction[i].value, c.reduction_spread[i].spread.median);
  }
  // The compute body's curve at the same K, floored at 1 as the memory body's; the memory
  // body's time per byte alone is the median of its samples.
  ASSERT_EQ(c.compute_inflation.size(), c.inflation.size());
  ASSERT_EQ(c.compute_inflation_spread.size(), c.inflation_spread.size());
  for (std::size_t i = 0; i < c.compute_inflation_spread.size(); ++i)
    EXPECT_EQ(c.compute_inflation[i + 1].value,
              std::max(1.0, c.compute_inflation_spread[i].spread.median));
  EXPECT_GT(c.inflation_ns_per_byte, 0.0);
  EXPECT_EQ(c.inflation_ns_per_byte, c.inflation_pass_spread.median);
  const nlohmann::json j = nlohmann::json::parse(calibration_json(c));
  EXPECT_EQ(j["samples"], 3);
  EXPECT_EQ(j["spread"]["park_wake_ns"]["median"].get<double>(), c.park_wake_ns);
  EXPECT_EQ(j["spread"]["inflation"][0]["threads"], c.inflation_spread[0].threads);
  const CostModel m = parse_calibration(calibration_json(c), "cal.json");
  EXPECT_EQ(m.park_wake_ns, c.park_wake_ns);
  EXPECT_EQ(m.inflation, c.inflation);
  EXPECT_EQ(m.compute_inflation, c.compute_inflation);
  EXPECT_EQ(m.inflation_ns_per_byte, c.inflation_ns_per_byte);
  // Interruptions at every K of the inflation (K = 1 included), one entry per thread: the
  // share lost in [0, 0.5], at most 32 sorted gap lengths, each at least the threshold.
  ASSERT_EQ(c.interruptions.size(), c.inflation.size());
  for (std::size_t i = 0; i < c.interruptions.size(); ++i) {
    EXPECT_EQ(c.interruptions[i].threads, c.inflation[i].threads);
    ASSERT_EQ(c.interruptions[i].cpus.size(), c.interruptions[i].threads);
    for (const ThreadInterruptions& t : c.interruptions[i].cpus) {
      EXPECT_GE(t.lost, 0.0);
      EXPECT_LE(t.lost, 0.5);
      EXPECT_LE(t.lengths_ns.size(), 32u);
      EXPECT_TRUE(std::is_sorted(t.lengths_ns.begin(), t.lengths_ns.end()));
      for (double l : t.lengths_ns) EXPECT_GE(l, kInterruptionGapNs);
      EXPECT_EQ(t.lost > 0, !t.lengths_ns.empty());
    }
  }
  EXPECT_EQ(m.interruptions, c.interruptions);
}

}  // namespace
}  // namespace tgraph::model
