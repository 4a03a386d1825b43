// SPDX-License-Identifier: MIT
// run_scene, capture_scene and validate_scene: their reports' keys and their refusals.
#include "tgraph/ode/run.hpp"

#include <gtest/gtest.h>
#include <unistd.h>

#include <cstdio>
#include <nlohmann/json.hpp>
#include <set>

#include "tgraph/graph/error.hpp"
#include "tgraph/graph/trace_io.hpp"
#include "tgraph/ode/scenes.hpp"

namespace tgraph::ode {
namespace {

TEST(OdeRun, ReportsTheSpeedUpsTheCheckAndEachStep) {
  RunOptions o = run_options("ode-chains", 5, choose_method("worksteal"), 2);
  o.check = true;
  const RunResult r = run_scene(o);
  // Work stealing runs ODE's own algorithm: within the seeds' spread (docs/ode.md, "The check").
  EXPECT_TRUE(r.check == "identical" || r.check == "within-rounding" ||
              r.check == "within-tolerance")
      << r.check << ": " << r.max_abs_diff << " m, tolerance " << r.tolerance << " m";
  const auto j = nlohmann::json::parse(to_json(r));
  for (const char* key : {"speedup", "world_speedup", "check", "sequential_wall_ns", "breakdown",
                          "per_step", "threads", "method", "calls_per_step"})
    EXPECT_TRUE(j.contains(key)) << key;
  EXPECT_EQ(j["per_step"].size(), 5u);
  EXPECT_EQ(j["threads"], 2);
  EXPECT_EQ(j["method"], "worksteal");
  EXPECT_GT(j["speedup"].get<double>(), 0.0);
  EXPECT_GT(j["calls_per_step"].get<double>(), 0.0);
  EXPECT_GT(j["breakdown"]["collide_ns"].get<std::int64_t>(), 0);
}

TEST(OdeRun, SequentialIsIdenticalToItself) {
  RunOptions o = run_options("ode-piles", 3, choose_method("sequential"), 2);
  o.check = true;
  EXPECT_EQ(run_scene(o).check, "identical");
}

TEST(OdeRun, OneThreadOfTgraphsRuntimeIsIdenticalToOdeSelfThreaded) {
  // One thread runs the calls in an order ODE's own self-threaded stepping also takes.
  RunOptions o = run_options("ode-piles", 10, choose_method("worksteal"), 1);
  o.check = true;
  EXPECT_EQ(run_scene(o).check, "identical");
}

TEST(OdeRun, DWorldStepOnTwoThreadsIsWithinTheSpreadOfAnotherContactOrder) {
  // dWorldStep has no random reordering; two island jobs make the next step's contacts in
  // another order (docs/ode.md, "The check"), which its LCP on these piles turns into
  // centimetres: the tolerance is what another contact order does to ODE self-threaded.
  RunOptions o =
      run_options("ode-piles", 40, choose_method("islands-serial"), 2, 1, Stepper::kStep);
  o.check = true;
  const RunResult r = run_scene(o);
  EXPECT_NE(r.check, "differs") << r.max_abs_diff << " m, tolerance " << r.tolerance << " m";
  if (r.check == "within-tolerance") {
    EXPECT_LE(r.max_abs_diff, r.tolerance);
  }
}

TEST(OdeRun, ADifferingCheckFailsWithOneLineNamingTheDistanceAndTheTolerance) {
  RunResult r;
  r.check = "differs";
  r.max_abs_diff = 0.5;
  r.tolerance = 0.125;
  const std::string line = differs_line(r);
  EXPECT_EQ(line.rfind("final state differs from ODE self-threaded's by 0.500000 m, more than "
                       "the tolerance (0.125000 m: five times",
                       0),
            0u)
      << line;
  EXPECT_EQ(line.find('\n'), std::string::npos) << line;
  // The basis the JSON gives.
  RunResult j = r;
  j.options = run_options("ode-piles", 1, choose_method("worksteal"), 2);
  const std::string basis = nlohmann::json::parse(to_json(j))["tolerance_basis"].get<std::string>();
  EXPECT_NE(line.find(basis), std::string::npos) << line;
}

TEST(OdeRun, RefusesBadOptionsByName) {
  RunOptions o;
  o.scene = "ode-nothing";
  EXPECT_THROW(run_scene(o), InputError);
  o.scene = "ode-piles";
  o.threads = 0;
  EXPECT_THROW(run_scene(o), OptionError);
  o.threads = 2;
  o.repeat = 0;
  EXPECT_THROW(run_scene(o), OptionError);
  ValidateOptions v;
  v.scene = "ode-piles";
  v.method = choose_method("ode");
  EXPECT_THROW(validate_scene(v), OptionError);
  v.method = choose_method("islands");  // no assignment of a captured step to simulate
  EXPECT_THROW(validate_scene(v), OptionError);
  CaptureOptions c;
  c.scene = "ode-piles";
  EXPECT_THROW(capture_scene(c), OptionError);  // no output
}

TEST(OdeCapture, WritesATraceOfOdesCallsThatReadsBack) {
  CaptureOptions o;
  o.scene = "ode-chains";
  o.steps = 3;
  o.output = "ode_capture_test_" + std::to_string(::getpid()) + ".tgt";
  const CaptureReport r = capture_scene(o);
  EXPECT_EQ(r.steps, 3u);
  const Trace t = read_trace(o.output);
  std::remove(o.output.c_str());
  ASSERT_EQ(t.steps.size(), 3u);
  std::set<std::string> kinds(t.steps[1].kinds.begin(), t.steps[1].kinds.end());
  EXPECT_TRUE(kinds.count("dWorldQuickStep"));
  EXPECT_TRUE(kinds.count("World Islands Stepping Group"));
  EXPECT_NE(t.header.engine.find("dWorldQuickStep"), std::string::npos);
  std::uint64_t tasks = 0;
  for (const StepGraph& g : t.steps) tasks += g.tasks.size();
  EXPECT_EQ(tasks, r.tasks);
  const nlohmann::json j = nlohmann::json::parse(to_json(r));
  EXPECT_EQ(j.at("scene"), "ode-chains");
  EXPECT_EQ(j.at("output"), o.output);
  EXPECT_EQ(j.at("steps"), 3);
  EXPECT_EQ(j.at("tasks"), tasks);
  EXPECT_EQ(j.at("edges"), r.edges);
  EXPECT_EQ(j.at("recorded_ns"), r.recorded_ns);
  EXPECT_EQ(j.at("unrecorded_ns"), r.unrecorded_ns);
  EXPECT_DOUBLE_EQ(j.at("capture_overhead").get<double>(), r.overhead);
  EXPECT_EQ(
      to_text(r).rfind("captured ode-chains: 3 steps, " + std::to_string(tasks) + " tasks", 0), 0u);
}

TEST(OdeValidate, ValidatesTheStepsARunWouldMakeUnlessTold) {
  // `tgraph validate --scene ode-*` without --steps: the scene's own steps, as run and capture.
  for (const char* scene : {"ode-piles", "ode-heap", "ode-chains"}) {
    const ValidateOptions o = validate_options(
        run_options(scene, std::nullopt, choose_method("worksteal"), 2, 3, Stepper::kQuickStep));
    EXPECT_EQ(o.steps, default_steps(scene)) << scene;
    EXPECT_EQ(o.repeat, 3u);
  }
  EXPECT_EQ(validate_options(
                run_options("ode-piles", 7u, choose_method("worksteal"), 2, 1, Stepper::kQuickStep))
                .steps,
            7u);
}

TEST(OdeValidate, PredictsTheLiveRunFromACapture) {
  ValidateOptions o;
  o.scene = "ode-chains";
  o.steps = 3;
  o.repeat = 1;
  o.method = choose_method("worksteal");
  const ValidateReport r = validate_scene(o);
  ASSERT_EQ(r.rounds.size(), 1u);
  EXPECT_GT(r.rounds[0].predicted_ns, 0);
  EXPECT_GT(r.predicted_over_live, 0.0);
  EXPECT_EQ(r.strategy, "list");
  const auto j = nlohmann::json::parse(to_json(r));
  EXPECT_TRUE(j.contains("predicted_over_live"));
  // The recording's own time per part, measured in the run and taken off the parts: never
  // negative, and reported.
  EXPECT_GE(r.recording_ns_per_part, 0.0);
  EXPECT_TRUE(j.contains("recording_ns_per_part"));
  EXPECT_TRUE(j.contains("live_speedup"));
}

}  // namespace
}  // namespace tgraph::ode
