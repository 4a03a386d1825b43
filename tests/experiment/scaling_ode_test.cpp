// SPDX-License-Identifier: MIT
// `tgraph experiment scaling --scenes ode-*`: the ODE scenes' runs through ode::run_scene, a
// record per method and thread count with the keys of every record and ODE's own figures.
#include <gtest/gtest.h>

#include <algorithm>
#include <nlohmann/json.hpp>
#include <set>
#include <string>
#include <vector>

#include "../option_error.hpp"
#include "tgraph/experiment/scaling.hpp"

namespace tgraph::experiment {
namespace {

#ifdef TGRAPH_HAVE_ODE

TEST(ScalingOde, TheOdeScenesRunOdesMethodsAndTheCommandSaysTheScenes) {
  ScalingOptions o;
  o.scenes = {"ode-piles", "ode-chains"};
  o.threads = {1, 2};
  o.out = "d";
  const ScalingPlan p = plan_scaling(o, 2);
  ASSERT_EQ(p.scenes.size(), 2u);
  EXPECT_TRUE(p.scenes[0].ode);
  EXPECT_EQ(p.scenes[0].steps, 200u);  // the scene's own, as `tgraph run` takes
  EXPECT_EQ(p.ode_methods, (std::vector<std::string>{"sequential", "ode", "worksteal", "islands",
                                                     "islands-serial", "list"}));
  EXPECT_EQ(p.methods_of(p.scenes[1]), p.ode_methods);
  EXPECT_EQ(p.runs(), 2 * (1 + 6 * 2u));
  EXPECT_EQ(p.command(),
            "scaling threads=1,2 methods=sequential,ode,worksteal,islands,islands-serial,list "
            "scenes=ode-piles,ode-chains steps=200 repeat=1 out=d");
  // A mix: each kind its own methods; a built-in scene by its label.
  o.scenes = {"bars64", "ode-heap"};
  o.quick = true;
  const ScalingPlan mixed = plan_scaling(o, 2);
  EXPECT_EQ(mixed.methods_of(mixed.scenes[0]), mixed.methods);
  EXPECT_EQ(mixed.methods_of(mixed.scenes[1]), mixed.ode_methods);
  EXPECT_EQ(mixed.scenes[1].steps, 40u);
}

TEST(ScalingOde, RefusesAnUnknownSceneAndAMethodOdeDoesNotTake) {
  const auto error = [](std::vector<std::string> scenes, std::vector<std::string> methods) {
    ScalingOptions o;
    o.scenes = std::move(scenes);
    o.methods = std::move(methods);
    return test::option_error([&o] { plan_scaling(o, 2); });
  };
  const std::string scene = error({"ode-piles", "nosuch"}, {});
  EXPECT_EQ(scene.rfind("scenes: unknown scene 'nosuch'", 0), 0u) << scene;
  const std::string method = error({"ode-piles"}, {"worksteal", "barrier"});
  EXPECT_EQ(method.rfind("methods: unknown method 'barrier' for the ODE scenes", 0), 0u) << method;
}

// A tiny sweep: 3 steps at 1 and 2 threads of ode-piles under ODE's six methods.
TEST(ScalingOde, ATinySweepGivesARecordPerMethodAndThreadCountWithOdesFigures) {
  ScalingOptions o;
  o.scenes = {"ode-piles"};
  o.threads = {1, 2};
  o.steps = 3;
  o.out = ::testing::TempDir() + "tgraph_scaling_ode";
  Progress progress(nullptr, false);
  const ScalingResult res = run_scaling(o, progress);
  EXPECT_TRUE(res.failed.empty()) << res.failed.front().reason;
  ASSERT_EQ(res.references.size(), 1u);
  EXPECT_EQ(res.references[0].scene, "ode-piles");
  EXPECT_EQ(res.references[0].steps, 3u);
  EXPECT_GT(res.references[0].sequential_wall_ns, 0);
  ASSERT_EQ(res.records.size(), 12u);
  const std::vector<std::pair<std::string, std::string>> order = {
      {"sequential", "sequential"},         {"ode", "ode"},
      {"worksteal", "worksteal"},           {"islands", "islands"},
      {"islands-serial", "islands-serial"}, {"partition", "list"}};
  for (std::size_t i = 0; i < res.records.size(); ++i) {
    const ScalingRecord& r = res.records[i];
    SCOPED_TRACE(r.method + " K=" + std::to_string(r.threads));
    EXPECT_EQ(r.threads, i < 6 ? 1u : 2u);  // every method at one count before the next
    EXPECT_EQ(r.policy, order[i % 6].first);
    EXPECT_EQ(r.method, order[i % 6].second);
    EXPECT_TRUE(r.ode);
    EXPECT_EQ(r.steps, 3u);
    EXPECT_GT(r.speedup, 0);
    ASSERT_TRUE(r.world_speedup);
    EXPECT_GT(*r.world_speedup, 0);
    EXPECT_GT(r.sequential_wall_ns, 0);
    EXPECT_GT(r.serial_share, 0);  // the collision
    // ODE self-threaded against itself, and ODE's pool of one thread, are bit for bit ODE.
    const std::set<std::string> checks = {"identical", "within-rounding", "within-tolerance"};
    EXPECT_TRUE(checks.count(r.check)) << r.check;
    if (r.method == "sequential") {
      EXPECT_EQ(r.check, "identical");
    }
    // The partition-guided method partitions the first step's graph (every 10th step).
    EXPECT_EQ(r.partitioned_steps, r.method == "list" ? 1u : 0u);
    EXPECT_FALSE(r.attribution);
  }
  // results.json: the keys of every record, then ODE's own; what is not measured is null.
  const nlohmann::json j = nlohmann::json::parse(scaling_json(res));
  const std::set<std::string> keys = {"scene",
                                      "policy",
                                      "method",
                                      "threads",
                                      "speedup",
                                      "serial_share",
                                      "inflation",
                                      "wait_share",
                                      "parks_per_step",
                                      "partitioned_steps",
                                      "predicted_speedup",
                                      "predicted_over_live",
                                      "attribution",
                                      "world_speedup",
                                      "check"};
  ASSERT_EQ(j["scaling"].size(), 12u);
  for (const nlohmann::json& r : j["scaling"]) {
    std::set<std::string> got;
    for (const auto& [k, v] : r.items()) got.insert(k);
    std::set<std::string> want = keys;
    if (r["check"] != "identical") want.insert("max_abs_diff");
    EXPECT_EQ(got, want) << r.dump();
    EXPECT_TRUE(r["inflation"].is_null());
    EXPECT_TRUE(r["predicted_speedup"].is_null());
  }
  EXPECT_EQ(j["ode_methods"], nlohmann::json(res.plan.ode_methods));
}

#else

TEST(ScalingOde, WithoutOdeTheOdeScenesAreRefusedSayingWhy) {
  ScalingOptions o;
  o.scenes = {"ode-piles"};
  EXPECT_EQ(test::option_error([&o] { plan_scaling(o, 2); })
                .rfind("scenes: 'ode-piles': the ODE "
                       "scenes are not in this build",
                       0),
            0u);
}

#endif

}  // namespace
}  // namespace tgraph::experiment
