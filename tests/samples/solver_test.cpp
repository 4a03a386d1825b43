// SPDX-License-Identifier: MIT
// Time integration: energy behaviour of the explicit and implicit schemes, and the CG loop.
#include <gtest/gtest.h>

#include <Eigen/Dense>
#include <algorithm>
#include <cmath>
#include <cstdio>

#include "test_util.hpp"
#include "tgraph/graph/metrics.hpp"

namespace tgraph::samples {
namespace {

// A free 5x5x5 mass-spring grid, no gravity, with a deterministic initial velocity field
// of zero total momentum.
std::unique_ptr<Scene> spring_block(const std::string& integrator, double dt) {
  char solver[128];
  std::snprintf(solver, sizeof solver, "solver integrator=%s dt=%g tolerance=1e-10 max_iterations=1000\n",
                integrator.c_str(), dt);
  auto s = parse_scene(test::scene_text("scene name=springs\n" + std::string(solver) +
                                        "gravity value=0,0,0\n"
                                        "springgrid name=b nodes=5,5,5 size=0.4,0.4,0.4 stiffness=500 density=100\n"),
                       "springs");
  StateVec& v = s->bodies()[0]->vec(VecId::kV);
  for (Index i = 0; i < v.cols(); ++i) {
    const auto x = static_cast<double>(i);
    v.col(i) = 0.5 * Vec3(std::sin(1.7 * x), std::cos(2.3 * x + 0.5), std::sin(0.9 * x + 2.0));
  }
  v.colwise() -= Vec3(v.rowwise().mean());
  return s;
}

TEST(ExplicitEuler, EnergyOfAnUndampedSpringSystemStaysBounded) {
  // Symplectic Euler conserves a modified energy: the total energy oscillates around its
  // initial value without drift.
  auto s = spring_block("explicit", 2e-4);
  const double e0 = s->kinetic_energy() + s->potential_energy();
  ASSERT_GT(e0, 0.1);
  double max_dev_first = 0.0, max_dev_last = 0.0;
  const int steps = 20000;
  for (int k = 0; k < steps; ++k) {
    test::run(*s, 1);
    const double dev = std::abs(s->kinetic_energy() + s->potential_energy() - e0) / e0;
    (k < steps / 2 ? max_dev_first : max_dev_last) = std::max(k < steps / 2 ? max_dev_first : max_dev_last, dev);
  }
  EXPECT_LT(max_dev_first, 0.05);
  EXPECT_LT(max_dev_last, 0.05);
  EXPECT_LT(max_dev_last, 2.0 * max_dev_first + 1e-3);  // no secular growth
  EXPECT_GT(s->potential_energy(), 1e-4 * e0);           // it does oscillate
}

TEST(ImplicitEuler, BackwardEulerDissipatesEnergy) {
  auto s = spring_block("implicit", 5e-3);
  double e = s->kinetic_energy() + s->potential_energy();
  const double e0 = e;
  for (int k = 0; k < 200; ++k) {
    test::run(*s, 1);
    const double en = s->kinetic_energy() + s->potential_energy();
    EXPECT_LE(en, e * (1 + 1e-9)) << "step " << k;
    e = en;
  }
  EXPECT_LT(e, 0.5 * e0);
}

// One bar of bars64's shape, alone, with a tight CG tolerance.
std::unique_ptr<Scene> small_bar(double tolerance, int max_iterations) {
  char solver[128];
  std::snprintf(solver, sizeof solver, "solver integrator=implicit dt=0.01 tolerance=%g max_iterations=%d\n",
                tolerance, max_iterations);
  return parse_scene(test::scene_text("scene name=bar\n" + std::string(solver) +
                                      "gravity value=0,-9.81,0\n"
                                      "fem name=bar nodes=6,3,3 size=0.5,0.2,0.2 center=0.25,0,0 young=1e6 fix=xmin\n"),
                     "bar");
}

TEST(ConjugateGradient, ReachesToleranceAndTheGraphRecordsItsIterations) {
  auto s = small_bar(1e-8, 1000);
  capture::Recorder rec(capture::Mode::kCapture);
  for (int step = 0; step < 5; ++step) {
    // Keep the state of the start of the step to rebuild the linear system.
    Body& b = *s->bodies()[0];
    const StateVec v0 = b.vec(VecId::kV);
    s->step(rec);
    const StepGraph g = rec.end_step();
    const StepStats st = s->last_stats();
    ASSERT_EQ(g.loops.size(), 1u);
    EXPECT_EQ(g.loops[0].iterations, st.cg_iterations);
    EXPECT_GT(st.cg_iterations, 1u);
    EXPECT_LT(st.cg_iterations, 1000u);
    EXPECT_LE(st.cg_residual, 1e-8);
    // True residual: assemble A = M - h^2 K column by column from addDForce (K as cached by
    // this step's addForce) and check A dv = b with b = h (f + h K v0), projected.
    const double h = s->solver().dt;
    const Index n = b.columns() * 3;
    Eigen::MatrixXd a(n, n);
    const FixedConstraint& fix = *s->constraints()[0];
    std::vector<ForceField*> stiff;
    for (const auto& ff : s->force_fields())
      if (ff->has_stiffness()) stiff.push_back(ff.get());
    const StateVec keep_p = b.vec(VecId::kP), keep_q = b.vec(VecId::kQ);
    for (Index j = 0; j < n; ++j) {
      b.vec(VecId::kP).setZero();
      b.vec(VecId::kP)(j % 3, j / 3) = 1.0;
      fix.project(b.vec(VecId::kP));
      b.vec(VecId::kQ).setZero();
      b.add_mdx(b.vec(VecId::kQ), b.vec(VecId::kP), 1.0);
      for (ForceField* ff : stiff) ff->add_dforce(VecId::kQ, VecId::kP, -h * h, -h);
      fix.project(b.vec(VecId::kQ));
      a.col(j) = Eigen::Map<const Eigen::VectorXd>(b.vec(VecId::kQ).data(), n);
    }
    b.vec(VecId::kP) = keep_p;
    b.vec(VecId::kQ) = keep_q;
    StateVec rhs = h * b.vec(VecId::kF);  // f already holds f + h K v0 (addDForce(f, v, h))
    fix.project(rhs);
    const Eigen::VectorXd bvec = Eigen::Map<const Eigen::VectorXd>(rhs.data(), n);
    const StateVec dv = b.vec(VecId::kV) - v0;
    const Eigen::VectorXd x = Eigen::Map<const Eigen::VectorXd>(dv.data(), n);
    EXPECT_LT((a * x - bvec).norm(), 1e-6 * bvec.norm()) << "step " << step;
    EXPECT_LT((dv - b.vec(VecId::kDv)).norm(), 1e-12 * (1 + dv.norm()));
  }
}

TEST(ConjugateGradient, StopsAtMaxIterationsAndRecordsThem) {
  auto s = small_bar(1e-14, 3);
  capture::Recorder rec(capture::Mode::kCapture);
  s->step(rec);
  const StepGraph g = rec.end_step();
  ASSERT_EQ(g.loops.size(), 1u);
  EXPECT_EQ(g.loops[0].iterations, 3u);
  EXPECT_EQ(g.loops[0].max_iterations, 3u);
  EXPECT_EQ(s->last_stats().cg_iterations, 3u);
  EXPECT_GT(s->last_stats().cg_residual, 1e-14);
}

}  // namespace
}  // namespace tgraph::samples

namespace tgraph::samples {
namespace {

TEST(RigidBody, TorqueFreeSpinKeepsAngularMomentumAndEnergy) {
  // An asymmetric box spinning about a tilted axis precesses; its angular momentum is
  // conserved exactly by the orientation update, its kinetic energy to the step's order.
  auto s = parse_scene(test::scene_text("scene name=spin\nsolver integrator=explicit dt=0.001\n"
                                        "gravity value=0,0,0\n"
                                        "rigid name=b shape=box size=0.4,0.2,0.1 res=4 density=1000\n"),
                       "spin");
  auto* b = dynamic_cast<RigidBody*>(s->bodies()[0].get());
  ASSERT_NE(b, nullptr);
  b->vec(VecId::kV).col(1) = Vec3(0.3, 5.0, 0.4);
  const Vec3 l0 = b->angular_momentum();
  const double e0 = b->kinetic_energy();
  const Eigen::Quaterniond q0 = b->orientation();
  test::run(*s, 3000);
  EXPECT_LT((b->angular_momentum() - l0).norm(), 1e-9 * l0.norm());
  EXPECT_NEAR(b->kinetic_energy(), e0, 0.02 * e0);
  EXPECT_GT(q0.angularDistance(b->orientation()), 0.1);  // it did rotate
  EXPECT_LT(b->vec(VecId::kX).col(0).norm(), 1e-12);     // no drift of the centre
}

}  // namespace
}  // namespace tgraph::samples
