// SPDX-License-Identifier: MIT
// The scenes' physics (docs/ode.md, "Scenes"), stepped by ODE self-threaded and through
// tgraph's runtime: nothing below the floor, the heap at rest, the chains' joints holding.
#include <gtest/gtest.h>

#include "tgraph/ode/attach.hpp"
#include "tgraph/ode/scenes.hpp"

namespace tgraph::ode {
namespace {

// Tolerances, physical and fixed here before any run:
// - a box's lowest vertex at most 1 cm below the floor (soft contacts, soft_erp 0.5, let a
//   box sink a few millimetres; a box through the floor is 0.3-0.5 m below);
// - at rest: the boxes' kinetic energy that of every box moving at 5 cm/s (their
//   root-mean-square speed below 0.05 m/s; ODE's 20 Gauss-Seidel iterations leave a few boxes
//   of a heap jittering, so no single box's speed is the criterion);
// - joints: a hinge's two anchors at most 5 % of a link's length apart (ODE corrects joint
//   error at ERP 0.2 a step; 20 Gauss-Seidel iterations leave a residual along a chain).
constexpr double kFloorDepth = 0.01;
constexpr double kRestSpeed = 0.05;
constexpr double kJointError = 0.05;

class OdePhysics : public ::testing::TestWithParam<const char*> {
 protected:
  void SetUp() override { dInitODE2(0); }
  void TearDown() override { dCloseODE(); }
  void run(Scene& scene, std::uint32_t steps) {
    if (std::string(GetParam()) == "sequential") {
      for (std::uint32_t i = 0; i < steps; ++i) scene.step(nullptr);
      return;
    }
    AttachOptions o;
    o.method = choose_method(GetParam());
    o.threads = 2;
    Attachment attach(scene.world(), o);
    for (std::uint32_t i = 0; i < steps; ++i) scene.step(&attach);
  }
};

TEST_P(OdePhysics, PilesStayAboveTheFloor) {
  auto scene = Scene::make("ode-piles");
  run(*scene, 200);
  EXPECT_LT(scene->depth_below_floor(), kFloorDepth);
}

TEST_P(OdePhysics, HeapComesToRestInItsBin) {
  auto scene = Scene::make("ode-heap");
  run(*scene, 600);  // 3 s: the overhanging bricks fall, tumble and settle
  EXPECT_LT(scene->depth_below_floor(), kFloorDepth);
  EXPECT_LT(scene->rms_speed(), kRestSpeed);
}

TEST_P(OdePhysics, ChainLinksStayWithinJointErrorOfTheirLength) {
  auto scene = Scene::make("ode-chains");
  run(*scene, 200);
  EXPECT_LT(scene->max_joint_error(), kJointError);
  EXPECT_LT(scene->depth_below_floor(), kFloorDepth);
}

INSTANTIATE_TEST_SUITE_P(Methods, OdePhysics, ::testing::Values("sequential", "worksteal"));

}  // namespace
}  // namespace tgraph::ode
