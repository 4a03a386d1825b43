// SPDX-License-Identifier: MIT
#include "tgraph/experiment/scaling.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <fstream>
#include <string>
#include <vector>

#include "../option_error.hpp"
#include "count_errors.hpp"
#include "tgraph/graph/error.hpp"

namespace tgraph::experiment {
namespace {

std::vector<std::string> labels(const ScalingPlan& p) {
  std::vector<std::string> out;
  for (const ScalingScene& s : p.scenes) out.push_back(s.label() + ":" + std::to_string(s.steps));
  return out;
}

TEST(ScalingThreads, DefaultIsThePowersOfTwoUpToTheCoresAndTheCoresThemselves) {
  EXPECT_EQ(scaling_thread_list(1), (std::vector<std::uint32_t>{1}));
  EXPECT_EQ(scaling_thread_list(2), (std::vector<std::uint32_t>{1, 2}));
  EXPECT_EQ(scaling_thread_list(12), (std::vector<std::uint32_t>{1, 2, 4, 8, 12}));
  EXPECT_EQ(scaling_thread_list(16), (std::vector<std::uint32_t>{1, 2, 4, 8, 16}));
}

TEST(ScalingPlan, DefaultsAreTheFourScenesEveryMethodAndOnePass) {
  const ScalingPlan p = plan_scaling({}, 16);
  EXPECT_EQ(labels(p), (std::vector<std::string>{"bars64:20", "falling64:60", "torso:60",
                                                 "cloth256-s64:5"}));
  for (const char* m : {"owner", "metis", "sticky", "worksteal", "barrier", "omp-tasks"})
    EXPECT_NE(std::find(p.methods.begin(), p.methods.end(), m), p.methods.end()) << m;
#ifdef TGRAPH_HAVE_STARPU
  EXPECT_EQ(p.methods.back(), "starpu");
#endif
  EXPECT_EQ(p.threads, (std::vector<std::uint32_t>{1, 2, 4, 8, 16}));
  EXPECT_EQ(p.repeat, 1u);
  EXPECT_EQ(p.out_dir, "tgraph-experiment-scaling");
  EXPECT_EQ(p.runs(), 4 * (1 + p.methods.size() * 5));
}

TEST(ScalingPlan, QuickRunsFewStepsOnOneAndTwoThreadsOfEveryScene) {
  ScalingOptions o;
  o.quick = true;
  const ScalingPlan p = plan_scaling(o, 16);
  EXPECT_EQ(labels(p), (std::vector<std::string>{"bars64:2", "falling64:3", "torso:3",
                                                 "cloth256-s64:1"}));
  EXPECT_EQ(p.threads, (std::vector<std::uint32_t>{1, 2}));
  EXPECT_EQ(p.methods, (std::vector<std::string>{"owner", "sticky", "worksteal", "barrier"}));
  EXPECT_NE(p.command().find("quick threads=1,2 methods=owner,sticky,worksteal,barrier"),
            std::string::npos)
      << p.command();
}

TEST(ScalingPlan, FlagsOverrideTheDefaultsAndCountsAboveTheCoresAreNoted) {
  ScalingOptions o;
  o.threads = {4, 1};
  o.methods = {"sticky", "worksteal", "sticky"};
  o.steps = 7;
  o.repeat = 3;
  o.out = "d";
  const ScalingPlan p = plan_scaling(o, 2);
  EXPECT_EQ(p.threads, (std::vector<std::uint32_t>{1, 4}));
  EXPECT_EQ(p.methods, (std::vector<std::string>{"sticky", "worksteal"}));
  for (const ScalingScene& s : p.scenes) EXPECT_EQ(s.steps, 7u) << s.label();
  EXPECT_EQ(p.repeat, 3u);
  EXPECT_EQ(p.command(), "scaling threads=1,4 methods=sticky,worksteal steps=7 repeat=3 out=d");
  ASSERT_EQ(p.notes.size(), 1u);
  EXPECT_NE(p.notes[0].find("oversubscribed"), std::string::npos) << p.notes[0];
}

TEST(ScalingPlan, RejectsBadOptionsNamingTheField) {
  ScalingOptions o;
  const auto error = [&o] { return test::option_error([&o] { plan_scaling(o, 2); }); };
  for (const char* bad : {"nosuch", "sequential", "partition"}) {
    o.methods = {"owner", bad};
    EXPECT_EQ(error().rfind("methods: ", 0), 0u) << bad;
  }
  o = {};
  o.threads = {0};
  EXPECT_EQ(error(), "threads: 0 threads is out of range (expected 1 to 1024)");
  test::expect_zero_counts_refused<ScalingOptions>(
      [](const ScalingOptions& x) { plan_scaling(x, 2); });
}

// --calibration: read when the sweep is planned (a bad file stops it before its first run,
// naming the file) and written into the command that reproduces it.
TEST(ScalingPlan, ACalibrationFileIsReadBeforeAnyRunAndWrittenInTheCommand) {
  const std::string dir = ::testing::TempDir();
  const std::string good = dir + "tgraph_scaling_cal.json", bad = dir + "tgraph_scaling_bad.json";
  std::ofstream(good) << R"({"sync_latency_ns": 80, "per_byte_ns": 0.02})";
  std::ofstream(bad) << R"({"sync_latency_ns": "fast", "per_byte_ns": 0.02})";
  ScalingOptions o;
  o.threads = {1, 2};
  o.methods = {"owner"};
  o.steps = 3;
  o.repeat = 1;
  o.out = "d";
  o.calibration = good;
  const ScalingPlan p = plan_scaling(o, 2);
  EXPECT_EQ(p.calibration, good);
  EXPECT_EQ(p.command(),
            "scaling threads=1,2 methods=owner steps=3 repeat=1 calibration=" + good + " out=d");
  for (const std::string& file : {bad, dir + "tgraph_no_such_calibration.json"}) {
    o.calibration = file;
    const std::string error = test::input_error([&o] { plan_scaling(o, 2); });
    EXPECT_NE(error.find(file), std::string::npos) << error;
  }
}

}  // namespace
}  // namespace tgraph::experiment
