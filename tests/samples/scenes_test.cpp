// SPDX-License-Identifier: MIT
// The built-in scenes: their graphs, collision behaviour, determinism and the scene files.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <set>
#include <sstream>

#include "test_util.hpp"
#include "tgraph/graph/error.hpp"
#include "tgraph/graph/metrics.hpp"

namespace tgraph::samples {
namespace {

TEST(Scenes, EveryBuiltInSceneIsTheFileUnderSamplesScenes) {
  const std::vector<std::string> expected = {"bars64", "cloth128", "cloth256", "cloth512", "falling", "falling64", "fig2", "torso-small", "torso"};
  EXPECT_EQ(builtin_scene_names(), expected);
  for (const std::string& name : builtin_scene_names()) {
    std::ifstream in(std::string(TGRAPH_SCENES_DIR) + "/" + name + ".scene");
    ASSERT_TRUE(in) << name;
    std::stringstream ss;
    ss << in.rdbuf();
    EXPECT_EQ(ss.str(), *builtin_scene_text(name)) << name;
    // Built from the file path, the scene is the same.
    auto a = make_scene(name);
    auto b = make_scene(std::string(TGRAPH_SCENES_DIR) + "/" + name + ".scene");
    EXPECT_EQ(a->name(), name);
    EXPECT_EQ(a->bodies().size(), b->bodies().size());
    EXPECT_EQ(a->force_fields().size(), b->force_fields().size());
  }
}

TEST(Scenes, Bars64HasSixtyFourIdenticalBarsInOneCgLoop) {
  auto s = make_scene("bars64");
  ASSERT_EQ(s->bodies().size(), 64u);
  for (const auto& b : s->bodies()) EXPECT_EQ(b->columns(), 16 * 4 * 4);
  capture::Recorder rec(capture::Mode::kCapture);
  s->step(rec);
  StepGraph g = rec.end_step();
  ASSERT_EQ(g.validate(), "");
  // Per bar: 7 tasks before the loop, 6 in its body, 2 after; plus the solver's scalar tasks
  // (cgInit, cgStart; cgScalars and the loop break in the body).
  EXPECT_EQ(g.tasks.size(), 64u * (7 + 6 + 2) + 4);
  ASSERT_EQ(g.loops.size(), 1u);
  EXPECT_EQ(g.loops[0].last - g.loops[0].first, 64u * 6 + 2);
  EXPECT_GT(g.loops[0].iterations, 1u);
  EXPECT_EQ(g.loops[0].iterations, s->last_stats().cg_iterations);
  EXPECT_LT(s->last_stats().cg_residual, s->solver().tolerance);
  EXPECT_TRUE(g.contacts.empty());
  // Structural parallelism with equal task costs: the 64 bars run side by side.
  for (Task& t : g.tasks) t.cost_ns = 1000;
  EXPECT_GE(compute_metrics(g).parallelism, 16.0);
  // The next step has the same structure.
  s->step(rec);
  EXPECT_TRUE(rec.end_step().same_structure(g));
}

TEST(Scenes, FallingRecordsItsCollisionDetectionAsTheStepsHostTime) {
  // The host part of collision detection (merging contact sets, collision groups) runs on the
  // engine's thread before the step's tasks: each step carries its duration, which replays and
  // the simulator pay.
  auto s = make_scene("falling");
  capture::Recorder rec(capture::Mode::kCapture);
  for (int k = 0; k < 3; ++k) {
    s->step(rec);
    EXPECT_GT(rec.end_step().host_ns, 0u) << "step " << k;
  }
}

TEST(Scenes, FallingMergesIntoOneCollisionGroup) {
  auto s = make_scene("falling");
  capture::Recorder rec(capture::Mode::kCapture);
  std::set<std::uint64_t> shapes;
  std::vector<Contact> prev;
  int changes = 0;
  std::uint32_t first_groups = 0;
  for (int k = 0; k < s->default_steps(); ++k) {
    s->step(rec);
    const StepGraph g = rec.end_step();
    shapes.insert(g.structural_hash());
    if (k > 0 && g.contacts != prev) ++changes;
    prev = g.contacts;
    if (k == 0) first_groups = s->last_stats().groups;
    // Every group has its own CG loop.
    EXPECT_EQ(g.loops.size(), s->last_stats().groups);
  }
  EXPECT_GE(first_groups, 8u);  // the falling objects start apart
  EXPECT_EQ(s->last_stats().groups, 1u);
  EXPECT_GT(changes, 0);
  EXPECT_GT(shapes.size(), 1u);
  EXPECT_EQ(rec.errors(), 0u);
}

TEST(Collision, TwoFallingObjectsComeToRestWithoutInterpenetrating) {
  auto s = parse_scene(test::scene_text(
                           "scene name=stack\n"
                           "solver integrator=implicit dt=0.005 tolerance=1e-6 max_iterations=500\n"
                           "gravity value=0,-9.81,0\n"
                           "collision stiffness=2e4 alarm=0.03 damping=2 friction=2 floor=0 floor_friction=5\n"
                           "rigid name=box shape=box size=0.4,0.2,0.4 res=11 density=500 center=0,0.3,0 damping=1\n"
                           "fem name=cube nodes=6,6,6 size=0.25,0.25,0.25 center=0.02,0.8,-0.01 young=2e5 "
                           "density=500 damping=1\n"),
                       "stack");
  Body& box = *s->bodies()[0];
  Body& cube = *s->bodies()[1];
  bool touched = false;
  for (int k = 0; k < 500; ++k) {
    test::run(*s, 1);
    touched = touched || s->last_stats().groups == 1;
  }
  EXPECT_TRUE(touched);
  EXPECT_EQ(s->last_stats().groups, 1u);  // resting on each other
  EXPECT_LT(s->kinetic_energy(), 1e-3);
  // No interpenetration of the sphere proxies beyond 25% of their radii, and the cube's
  // lowest surface point stays above the box's highest one (minus that tolerance).
  const double r = box.contact_radius + cube.contact_radius;
  double dmin = 1e9, cube_low = 1e9, box_high = -1e9;
  for (Index i : cube.surface) {
    cube_low = std::min(cube_low, cube.point(i).y());
    for (Index j : box.surface) dmin = std::min(dmin, (cube.point(i) - box.point(j)).norm());
  }
  for (Index j : box.surface) box_high = std::max(box_high, box.point(j).y());
  EXPECT_GT(dmin, 0.75 * r);
  EXPECT_GT(cube_low, box_high - 0.25 * r);
  EXPECT_LT(cube_low - box_high, r + 0.01);  // resting on it, not floating
  // The box rests on the floor (y = 0) at its proxies' radius.
  double box_low = 1e9;
  for (Index j : box.surface) box_low = std::min(box_low, box.point(j).y());
  EXPECT_NEAR(box_low, box.contact_radius, 0.25 * box.contact_radius);
}

std::vector<StateVec> positions(const Scene& s) {
  std::vector<StateVec> out;
  for (const auto& b : s.bodies()) out.push_back(b->vec(VecId::kX));
  return out;
}

TEST(Determinism, SameSeedSameResultDifferentSeedDifferentStart) {
  SceneOptions o;
  o.seed = 7;
  auto a = make_scene("falling", o);
  auto b = make_scene("falling", o);
  o.seed = 8;
  auto c = make_scene("falling", o);
  EXPECT_NE(positions(*a), positions(*c));
  test::run(*a, 120);
  // The same steps recorded in capture mode give bit-identical physics.
  capture::Recorder rec(capture::Mode::kCapture);
  for (int k = 0; k < 120; ++k) {
    b->step(rec);
    rec.end_step();
  }
  EXPECT_EQ(positions(*a), positions(*b));
  EXPECT_EQ(a->last_stats().cg_iterations, b->last_stats().cg_iterations);
}

TEST(Deferred, ProgramsRunSequentiallyReproduceTheCapturedSteps) {
  // The coordination code records runnable bodies: executing each deferred step program in
  // program order (loops repeated until their condition) gives the captured physics bit for
  // bit, with the same loop iteration counts.
  auto a = make_scene("torso-small");
  auto b = make_scene("torso-small");
  capture::Recorder cap(capture::Mode::kCapture);
  capture::Recorder def(capture::Mode::kDeferred);
  for (int k = 0; k < 30; ++k) {
    a->step(cap);
    const StepGraph g = cap.end_step();
    b->step(def);
    capture::StepProgram p = def.end_step_program();
    ASSERT_TRUE(p.graph.same_structure(g)) << "step " << k;
    ASSERT_EQ(p.bodies.size(), p.graph.tasks.size());
    const auto iterations = test::run_program(p);
    ASSERT_EQ(iterations.size(), g.loops.size());
    for (std::size_t l = 0; l < g.loops.size(); ++l) EXPECT_EQ(iterations[l], g.loops[l].iterations) << k;
  }
  EXPECT_EQ(positions(*a), positions(*b));
  EXPECT_EQ(cap.errors(), 0u);
  EXPECT_EQ(def.errors(), 0u);
}

TEST(Cloth, CuttingTheSheetIntoSubObjectsDoesNotChangeThePhysics) {
  auto cloth = [](int split) {
    return parse_scene(test::scene_text("scene name=c\nsolver integrator=implicit dt=0.005 tolerance=1e-12 "
                                        "max_iterations=5000\ngravity value=0,-9.81,0\n"
                                        "cloth name=c nodes=12 split=" +
                                        std::to_string(split) +
                                        " size=0.11 stiffness=2000 shear=1000 bend=200 mass=0.072 fix=edge\n"),
                       "c");
  };
  auto whole = cloth(1);
  auto cut = cloth(3);
  EXPECT_EQ(whole->bodies().size(), 1u);
  EXPECT_EQ(cut->bodies().size(), 9u);
  test::run(*whole, 40);
  test::run(*cut, 40);
  EXPECT_EQ(cut->last_stats().groups, 1u);  // interaction springs tie all sub-objects
  // Gather the cut sheet's nodes by position order and compare with the whole sheet.
  std::vector<std::array<double, 3>> pw, pc;
  for (const auto& b : whole->bodies())
    for (Index i = 0; i < b->columns(); ++i) pw.push_back({b->vec(VecId::kX)(0, i), b->vec(VecId::kX)(1, i), b->vec(VecId::kX)(2, i)});
  for (const auto& b : cut->bodies())
    for (Index i = 0; i < b->columns(); ++i) pc.push_back({b->vec(VecId::kX)(0, i), b->vec(VecId::kX)(1, i), b->vec(VecId::kX)(2, i)});
  // Rest x, z identify nodes; compare by sorting on (rest x, rest z) via the same grid order.
  ASSERT_EQ(pw.size(), pc.size());
  std::sort(pw.begin(), pw.end());
  std::sort(pc.begin(), pc.end());
  double maxdiff = 0.0;
  for (std::size_t i = 0; i < pw.size(); ++i)
    for (int c = 0; c < 3; ++c) maxdiff = std::max(maxdiff, std::abs(pw[i][static_cast<std::size_t>(c)] - pc[i][static_cast<std::size_t>(c)]));
  EXPECT_LT(maxdiff, 1e-8);
  EXPECT_LT(whole->potential_energy() - cut->potential_energy(), 1e-9);
}

std::string error_of(const std::string& text) {
  try {
    parse_scene(text, "bad.scene");
  } catch (const InputError& e) {
    return e.what();
  }
  return "(no error)";
}

TEST(SceneFile, BadFilesGiveOneLineErrorsNamingFileAndLine) {
  EXPECT_EQ(error_of(""), "bad.scene:0: empty scene file (the first line must be 'tgraph-scene 1')");
  EXPECT_EQ(error_of("scene name=x\n"), "bad.scene:1: the first line must be 'tgraph-scene 1'");
  EXPECT_EQ(error_of("tgraph-scene 2\n"), "bad.scene:1: the first line must be 'tgraph-scene 1'");
  EXPECT_EQ(error_of(test::scene_text("scene name=x\nwobble a=1\n")), "bad.scene:3: unknown directive 'wobble'");
  EXPECT_EQ(error_of(test::scene_text("# c\nscene name=x\nsolver dt=fast\n")), "bad.scene:4: dt: 'fast' is not a number");
  EXPECT_EQ(error_of(test::scene_text("scene name=x\nsolver dt=-1\n")), "bad.scene:3: dt must be > 0 (got -1)");
  EXPECT_EQ(error_of(test::scene_text("scene name=x\nsolver colour=red\n")),
            "bad.scene:3: unknown attribute 'colour' for 'solver'");
  EXPECT_EQ(error_of(test::scene_text("scene name=x\nfem name=a nodes=1,4,4 size=1,1,1\n")),
            "bad.scene:3: nodes: each value must be an integer in [2, 512]");
  EXPECT_EQ(error_of(test::scene_text("scene name=x\nparticles name=a points=0,0,0 mass=1\nsprings a=a b=zz pairs=0-0 "
                                      "stiffness=1\n")),
            "bad.scene:4: b: no object named 'zz' (objects must be declared first)");
  EXPECT_EQ(error_of(test::scene_text("scene name=x\nparticles name=a points=0,0 mass=1\n")),
            "bad.scene:3: points: expected 3 comma-separated numbers, got 2");
  EXPECT_EQ(error_of(test::scene_text("scene name=x\n")), "bad.scene:2: the scene has no objects");
  EXPECT_EQ(error_of(test::scene_text("fem name=a nodes=2,2,2 size=1,1,1\n")),
            "bad.scene:2: 'fem' before the 'scene name=...' line");
  EXPECT_EQ(error_of(test::scene_text("scene name=x\nrigid name=a shape=cone size=1\n")),
            "bad.scene:3: shape: 'cone' is not one of box, sphere");
  EXPECT_EQ(error_of(test::scene_text("scene name=x\nparticles name=a points=0,0,0 mass=1\n"
                                      "particles name=a points=0,0,0 mass=1\n")),
            "bad.scene:4: an object named 'a' already exists");
  EXPECT_THROW(make_scene("no-such-scene"), InputError);
}

}  // namespace
}  // namespace tgraph::samples
