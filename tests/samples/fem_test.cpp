// SPDX-License-Identifier: MIT
// Corotational hexahedral FEM: element matrix, rotation invariance, and the cantilever
// static deflection against Timoshenko beam theory under mesh refinement.
#include <gtest/gtest.h>

#include <Eigen/Eigenvalues>
#include <cmath>
#include <cstdio>
#include <string>
#include <vector>

#include "test_util.hpp"

namespace tgraph::samples {
namespace {

Eigen::Matrix<double, 3, 8> unit_cube(double hx, double hy, double hz) {
  Eigen::Matrix<double, 3, 8> r;
  const int c[8][3] = {{0, 0, 0}, {1, 0, 0}, {1, 1, 0}, {0, 1, 0}, {0, 0, 1}, {1, 0, 1}, {1, 1, 1}, {0, 1, 1}};
  for (int i = 0; i < 8; ++i) r.col(i) = Vec3(c[i][0] * hx, c[i][1] * hy, c[i][2] * hz);
  return r;
}

TEST(HexFem, ElementStiffnessIsSymmetricWithSixRigidModes) {
  for (bool incompatible : {false, true}) {
    FemMaterial m;
    m.young = 1e6;
    m.poisson = 0.3;
    m.incompatible_modes = incompatible;
    const auto k = HexFemForceField::element_stiffness(unit_cube(0.1, 0.2, 0.15), m);
    EXPECT_LT((k - k.transpose()).norm(), 1e-9 * k.norm());
    Eigen::SelfAdjointEigenSolver<HexFemForceField::Mat24> es(k);
    const auto ev = es.eigenvalues();
    for (int i = 0; i < 6; ++i) EXPECT_NEAR(ev[i], 0.0, 1e-8 * ev[23]) << "rigid mode " << i;
    EXPECT_GT(ev[6], 1e-4 * ev[23]);  // no spurious zero-energy mode
    // Translations produce no force.
    Eigen::Matrix<double, 24, 1> t;
    for (int i = 0; i < 8; ++i) t.segment<3>(3 * i) = Vec3(0.3, -0.2, 0.7);
    EXPECT_LT((k * t).norm(), 1e-9 * k.norm());
  }
}

// A small FEM block (no gravity) for the rotation tests.
std::unique_ptr<Scene> block() {
  return parse_scene(test::scene_text("scene name=block\nsolver integrator=explicit dt=0.001\ngravity value=0,0,0\n"
                                      "fem name=b nodes=4,3,3 size=0.3,0.2,0.2 young=1e5\n"),
                     "block");
}

HexFemForceField* fem_of(Scene& s) {
  for (const auto& ff : s.force_fields())
    if (auto* f = dynamic_cast<HexFemForceField*>(ff.get())) return f;
  return nullptr;
}

TEST(HexFem, RigidRotationProducesNoForce) {
  auto s = block();
  auto* body = dynamic_cast<ParticleBody*>(s->bodies()[0].get());
  const Mat3 rot = Eigen::AngleAxisd(1.1, Vec3(0.3, 1.0, -0.4).normalized()).toRotationMatrix();
  body->vec(VecId::kX) = (rot * body->rest()).colwise() + Vec3(1.0, 2.0, 3.0);
  body->vec(VecId::kF).setZero();
  fem_of(*s)->add_force();
  EXPECT_LT(body->vec(VecId::kF).norm(), 1e-9);
  EXPECT_LT(fem_of(*s)->potential_energy(), 1e-12);
}

TEST(HexFem, ForcesRotateWithTheDeformedBody) {
  // Corotational: deforming then rotating gives the rotated forces of the deformed body.
  auto s1 = block();
  auto s2 = block();
  auto* b1 = dynamic_cast<ParticleBody*>(s1->bodies()[0].get());
  auto* b2 = dynamic_cast<ParticleBody*>(s2->bodies()[0].get());
  StateVec deformed = b1->rest();
  for (Index i = 0; i < deformed.cols(); ++i) {
    const auto x = static_cast<double>(i);
    deformed.col(i) += 0.01 * Vec3(std::sin(3.0 * x), std::cos(5.0 * x), std::sin(7.0 * x + 1.0));
  }
  const Mat3 rot = Eigen::AngleAxisd(2.0, Vec3(1.0, -0.5, 0.2).normalized()).toRotationMatrix();
  b1->vec(VecId::kX) = deformed;
  b2->vec(VecId::kX) = rot * deformed;
  fem_of(*s1)->add_force();
  fem_of(*s2)->add_force();
  EXPECT_GT(b1->vec(VecId::kF).norm(), 1.0);
  EXPECT_LT((rot * b1->vec(VecId::kF) - b2->vec(VecId::kF)).norm(), 1e-8 * b1->vec(VecId::kF).norm());
  EXPECT_NEAR(fem_of(*s1)->potential_energy(), fem_of(*s2)->potential_energy(), 1e-10);
  // Newton's third law: internal forces sum to zero (force and torque).
  EXPECT_LT(b1->vec(VecId::kF).rowwise().sum().norm(), 1e-9 * b1->vec(VecId::kF).norm());
}

// Cantilever 1.5 x 0.3 x 0.3 m, clamped at x = 0, under its own weight; nt elements through
// the thickness and 5 nt along the length (cubic elements). The static state is reached by
// implicit Euler with a 1 s step (a Newton iteration on the static equations).
double tip_deflection(int nt, const std::string& element) {
  const int nl = 5 * nt;
  char line[512];
  std::snprintf(line, sizeof line,
                "fem name=beam nodes=%d,%d,%d size=1.5,0.3,0.3 center=0.75,0,0 young=1e8 poisson=0.3 "
                "density=1000 fix=xmin element=%s\n",
                nl + 1, nt + 1, nt + 1, element.c_str());
  auto scene = parse_scene(test::scene_text("scene name=cantilever\n"
                                            "solver integrator=implicit dt=1 tolerance=1e-9 max_iterations=20000\n"
                                            "gravity value=0,-9.81,0\n" +
                                            std::string(line)),
                           "cantilever");
  auto* p = dynamic_cast<ParticleBody*>(scene->bodies()[0].get());
  double prev = 0.0, tip = 0.0;
  for (int s = 0; s < 12; ++s) {
    test::run(*scene, 1);
    double sum = 0.0;
    int n = 0;
    for (Index i = 0; i < p->columns(); ++i)
      if (p->rest()(0, i) > 1.5 - 1e-9) {
        sum += p->vec(VecId::kX)(1, i) - p->rest()(1, i);
        ++n;
      }
    tip = -sum / n;
    if (s > 1 && std::abs(tip - prev) < 1e-6 * std::abs(tip)) break;
    prev = tip;
  }
  return tip;
}

double timoshenko_tip() {
  const double E = 1e8, nu = 0.3, L = 1.5, a = 0.3, rho = 1000, g = 9.81;
  const double I = a * a * a * a / 12, A = a * a, q = rho * g * A, G = E / (2 * (1 + nu));
  const double kappa = 10 * (1 + nu) / (12 + 11 * nu);  // Cowper, rectangular section
  return q * L * L * L * L / (8 * E * I) + q * L * L / (2 * kappa * G * A);
}

TEST(Cantilever, TrilinearHexahedraConvergeToTimoshenkoUnderRefinement) {
  // Fully integrated trilinear hexahedra lock in bending: stiff on coarse meshes.
  const double ref = timoshenko_tip();
  double prev_err = 1e9;
  for (int nt : {1, 2, 4, 8}) {
    const double err = std::abs(tip_deflection(nt, "trilinear") - ref) / ref;
    std::printf("trilinear, %d element(s) through the thickness: error %.2f%%\n", nt, 100 * err);
    EXPECT_LT(err, prev_err) << nt;
    prev_err = err;
  }
  EXPECT_LT(prev_err, 0.10);
}

TEST(Cantilever, IncompatibleModesRemoveLockingOnTheBars64Mesh) {
  // The bars64 mesh is 15 x 3 x 3 elements (nt = 3). Measured errors (this test's output):
  // trilinear about 8%, incompatible modes under 3% (the remaining gap is the 3D clamp
  // versus beam theory); refinement shrinks the error.
  const double ref = timoshenko_tip();
  const double coarse_trilinear = std::abs(tip_deflection(3, "trilinear") - ref) / ref;
  const double coarse = std::abs(tip_deflection(3, "incompatible") - ref) / ref;
  std::printf("bars64 mesh: trilinear error %.2f%%, incompatible modes error %.2f%%\n", 100 * coarse_trilinear,
              100 * coarse);
  EXPECT_LT(coarse, 0.05);
  EXPECT_LT(coarse, 0.5 * coarse_trilinear);
  double prev_err = 1e9;
  for (int nt : {2, 4, 8}) {
    const double err = std::abs(tip_deflection(nt, "incompatible") - ref) / ref;
    std::printf("incompatible modes, %d element(s) through the thickness: error %.2f%%\n", nt, 100 * err);
    EXPECT_LT(err, prev_err) << nt;
    prev_err = err;
  }
  EXPECT_LT(prev_err, 0.10);
}

TEST(Cantilever, LargeDeflectionStaysBoundedAndShortensTheSpan) {
  // A soft bar (static tip sag of linear theory: ~0.8 m, over half its length) bends
  // without the volume growth of linear FEM: the corotational tip moves back towards the
  // clamp and its distance to the clamp stays close to the bar's length.
  auto scene = parse_scene(test::scene_text("scene name=soft\n"
                                            "solver integrator=implicit dt=0.02 tolerance=1e-6 max_iterations=2000\n"
                                            "gravity value=0,-9.81,0\n"
                                            "fem name=bar nodes=16,4,4 size=1.5,0.3,0.3 center=0.75,0,0 young=1e6 "
                                            "density=1000 fix=xmin damping=2\n"),
                           "soft");
  test::run(*scene, 400);
  auto* p = dynamic_cast<ParticleBody*>(scene->bodies()[0].get());
  Vec3 tip = Vec3::Zero();
  int n = 0;
  for (Index i = 0; i < p->columns(); ++i)
    if (p->rest()(0, i) > 1.5 - 1e-9) {
      tip += p->vec(VecId::kX).col(i);
      ++n;
    }
  tip /= n;
  EXPECT_LT(tip.y(), -0.3);          // it bends a lot
  EXPECT_LT(tip.x(), 1.45);          // and the tip moves towards the wall
  EXPECT_NEAR(tip.norm(), 1.5, 0.1);  // no spurious stretching
  EXPECT_LT(scene->kinetic_energy(), 1e-2);
}

}  // namespace
}  // namespace tgraph::samples
