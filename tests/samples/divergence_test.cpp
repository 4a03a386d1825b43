// SPDX-License-Identifier: MIT
// Diverging simulations stop with the step, the object and the quantity; absurd settings are
// warned about or refused when the scene is built.
#include "tgraph/samples/divergence.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <string>

#include "test_util.hpp"
#include "tgraph/graph/error.hpp"

namespace tgraph::samples {
namespace {

std::string fig2_with(const std::string& solver) {
  return test::scene_text(
      "scene name=fig2\n" + solver +
      "\ngravity value=0,-9.81,0\n"
      "particles name=A points=0,0.2,0;0.1,0.2,0;0,0.2,0.1;0.1,0.2,0.1 mass=0.05\n"
      "particles name=B points=0,0,0;0.1,0,0;0,0,0.1;0.1,0,0.1 mass=0.05\n"
      "springs name=AB a=A b=B pairs=0-0,1-1,2-2,3-3 stiffness=50 rest=0.15\n");
}

// Runs until a DivergenceError or `steps` steps; returns it (step == max when none).
DivergenceError run_until_divergence(Scene& scene, int steps, capture::Mode mode) {
  capture::Recorder rec(mode);
  try {
    for (int s = 0; s < steps; ++s) {
      scene.step(rec);
      rec.end_step();
    }
  } catch (const DivergenceError& e) {
    return e;
  }
  return DivergenceError(std::numeric_limits<std::uint64_t>::max(), "", "", "none");
}

std::string falling_with(const std::string& from, const std::string& to) {
  std::string text(*builtin_scene_text("falling"));
  const auto at = text.find(from);
  EXPECT_NE(at, std::string::npos);
  return text.replace(at, from.size(), to);
}

TEST(Stability, BuiltInScenesGiveNoWarning) {
  for (const std::string& name : builtin_scene_names()) {
    const auto scene = make_scene(name);
    EXPECT_TRUE(scene->warnings().empty()) << name << ": " << scene->warnings().front();
  }
}

// Two 0.05 kg nodes joined by 50 N/m springs: omega^2 <= 2 k / m per node = 2000 1/s^2, so
// explicit Euler is guaranteed stable below dt = 2 / sqrt(2000) = 0.0447 s.
TEST(Stability, ExplicitTimeStepAboveTheLimitWarnsWithTheLimit) {
  EXPECT_TRUE(
      parse_scene(fig2_with("solver integrator=explicit dt=0.001"), "f")->warnings().empty());
  const auto scene = parse_scene(fig2_with("solver integrator=explicit dt=0.5"), "f.scene");
  ASSERT_EQ(scene->warnings().size(), 1u);
  const std::string& w = scene->warnings()[0];
  EXPECT_NE(w.find("f.scene:3: dt=0.5 s may be unstable for explicit Euler"), std::string::npos)
      << w;
  EXPECT_NE(w.find("dt < 2/omega_max = 0.0447 s"), std::string::npos) << w;
  EXPECT_NE(w.find("object 'AB'"), std::string::npos) << w;
}

TEST(Stability, StiffImplicitSystemWarnsThatCgCannotConverge) {
  const auto scene =
      parse_scene(fig2_with("solver integrator=implicit dt=1e6 max_iterations=50"), "f");
  ASSERT_EQ(scene->warnings().size(), 1u);
  EXPECT_NE(scene->warnings()[0].find("more than max_iterations=50"), std::string::npos)
      << scene->warnings()[0];
}

TEST(Stability, StiffnessThatOverflowsIsRefusedNamingTheLine) {
  try {
    parse_scene(falling_with("young=2e5", "young=1e308"), "falling.scene");
    ADD_FAILURE() << "accepted";
  } catch (const InputError& e) {
    const std::string m = e.what();
    EXPECT_NE(m.find("falling.scene:18: object 'cube': the stiffness overflows"), std::string::npos)
        << m;
  }
  std::string stiff = fig2_with("solver dt=0.001");
  stiff.replace(stiff.find("stiffness=50"), 12, "stiffness=1e300");
  EXPECT_THROW(parse_scene(stiff, "f"), InputError);
}

TEST(Divergence, ExplicitBlowUpStopsOnKineticEnergyNamingStepAndObject) {
  auto scene = parse_scene(fig2_with("solver integrator=explicit dt=0.5"), "f");
  const DivergenceError e = run_until_divergence(*scene, 100, capture::Mode::kCapture);
  ASSERT_LT(e.step(), 100u) << "never stopped";
  EXPECT_EQ(e.quantity(), "kinetic energy");
  EXPECT_TRUE(e.object() == "A" || e.object() == "B") << e.object();
  EXPECT_NE(std::string(e.what()).find("at step " + std::to_string(e.step()) + ": kinetic energy"),
            std::string::npos)
      << e.what();
}

TEST(Divergence, HugeTimeStepStopsAtStepZeroOnANonFiniteState) {
  SceneOptions options;
  options.dt = 1e308;
  auto scene = make_scene("falling", options);
  const DivergenceError e = run_until_divergence(*scene, 3, capture::Mode::kOff);
  EXPECT_EQ(e.step(), 0u);
  EXPECT_TRUE(e.quantity() == "position" || e.quantity() == "velocity") << e.quantity();
  EXPECT_NE(scene->find_body(e.object()), nullptr) << e.object();
  EXPECT_NE(std::string(e.what()).find("is not finite (node "), std::string::npos) << e.what();
}

TEST(Divergence, ANaNInjectedIntoOneBodyIsReportedWithItsNode) {
  auto scene = parse_scene(fig2_with("solver integrator=explicit dt=0.001"), "f");
  test::run(*scene, 2);
  scene->find_body("B")->vec(VecId::kV)(1, 2) = std::numeric_limits<double>::quiet_NaN();
  capture::Recorder rec(capture::Mode::kOff);
  try {
    scene->step(rec);
    ADD_FAILURE() << "no error";
  } catch (const DivergenceError& e) {
    EXPECT_EQ(e.step(), 2u);
    EXPECT_EQ(e.object(), "B");
    EXPECT_EQ(e.quantity(), "position");
    EXPECT_NE(std::string(e.what()).find("(node 2: "), std::string::npos) << e.what();
  }
}

// Deferred mode runs the tasks after step(): the next step() checks what they left.
TEST(Divergence, DeferredStepsAreCheckedAtTheNextStep) {
  auto scene = parse_scene(fig2_with("solver integrator=explicit dt=0.001"), "f");
  capture::Recorder rec(capture::Mode::kDeferred);
  scene->step(rec);
  capture::StepProgram p = rec.end_step_program();
  test::run_program(p);
  scene->find_body("A")->vec(VecId::kX)(0, 0) = std::numeric_limits<double>::infinity();
  try {
    scene->step(rec);
    ADD_FAILURE() << "no error";
  } catch (const DivergenceError& e) {
    EXPECT_EQ(e.step(), 0u);
    EXPECT_EQ(e.object(), "A");
    EXPECT_EQ(e.quantity(), "position");
  }
}

std::string bar(int max_iterations, int stall_steps) {
  return test::scene_text(
      "scene name=bar\nsolver integrator=implicit dt=0.01 tolerance=1e-14 "
      "max_iterations=" +
      std::to_string(max_iterations) + " cg_stall_steps=" + std::to_string(stall_steps) +
      "\ngravity value=0,-9.81,0\n"
      "fem name=bar nodes=6,3,3 size=0.5,0.2,0.2 young=1e6 fix=xmin\n");
}

TEST(Divergence, CgEndingAtItsLimitOnConsecutiveStepsStops) {
  auto scene = parse_scene(bar(2, 3), "bar");
  const DivergenceError e = run_until_divergence(*scene, 10, capture::Mode::kCapture);
  EXPECT_EQ(e.step(), 2u);  // the third consecutive unconverged solve
  EXPECT_EQ(e.object(), "solver[bar]");
  EXPECT_EQ(e.quantity(), "CG residual");
  EXPECT_NE(std::string(e.what()).find("max_iterations=2 without converging on 3 consecutive"),
            std::string::npos)
      << e.what();
  // Off: the same solves run on.
  auto off = parse_scene(bar(2, 0), "bar");
  EXPECT_EQ(run_until_divergence(*off, 10, capture::Mode::kCapture).step(),
            std::numeric_limits<std::uint64_t>::max());
}

TEST(Divergence, SettingsAreReadFromTheSolverLine) {
  const auto s = parse_scene(fig2_with("solver cg_stall_steps=4 energy_factor=3"), "f");
  EXPECT_EQ(s->solver().cg_stall_steps, 4u);
  EXPECT_EQ(s->solver().energy_factor, 3.0);
  EXPECT_THROW(parse_scene(fig2_with("solver energy_factor=0.5"), "f"), InputError);
  EXPECT_THROW(parse_scene(fig2_with("solver cg_stall_steps=-1"), "f"), InputError);
}

}  // namespace
}  // namespace tgraph::samples
