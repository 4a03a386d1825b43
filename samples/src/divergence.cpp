// SPDX-License-Identifier: MIT
// Divergence checks run by Scene::step (samples/scenes/README.md, "When a simulation
// diverges").
//
// The energy bound. Every force of the engine is either conservative with a potential that
// is >= 0 (springs, FEM, penalty contacts with other bodies and the floor), dissipative
// (Rayleigh mass damping, contact damping and friction), workless (fixed points), or
// gravity, whose work on the bodies is W(t) = U_g(0) - U_g(t). For such a system the total
// energy obeys K(t) + U(t) <= K(0) + U(0) + W(t); implicit Euler only dissipates more, and
// symplectic Euler, when stable, keeps the energy within a small bounded oscillation
// around it. Since U(t) >= 0, the kinetic energy alone is bounded:
//   K(t) <= K(0) + U(0) + W(t).
// An unstable integration grows K exponentially, so any factor above 1 catches it within a
// few steps; SolverSettings::energy_factor (10 by default) leaves room for the integrators'
// O(h) energy error. Only K and U_g are evaluated per step (one pass over the velocities and
// positions); U(0) (FEM energies need each element's rotation) is computed once.
#include "tgraph/samples/divergence.hpp"

#include <cmath>
#include <cstdio>
#include <string>

#include "scene_impl.hpp"

namespace tgraph::samples {

DivergenceError::DivergenceError(std::uint64_t step, std::string object, std::string quantity,
                                 const std::string& detail)
    : std::runtime_error("simulation diverged at step " + std::to_string(step) + ": " + quantity +
                         " of '" + object + "' " + detail),
      step_(step),
      object_(std::move(object)),
      quantity_(std::move(quantity)) {}

namespace detail {
namespace {

// Below this many joules the bound is not applied (a scene at rest, without gravity).
constexpr double kEnergyFloor = 1e-9;

std::string num(double v) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.6g", v);
  return buf;
}

// Throws if a state vector of `body` holds a NaN or an infinity. The sum of a vector is
// finite when every entry is (it can only also overflow, which the column scan then clears).
void check_finite(const Body& body, VecId id, const char* quantity, std::uint64_t step) {
  const StateVec& v = body.vec(id);
  if (std::isfinite(v.sum())) return;
  for (Index c = 0; c < v.cols(); ++c) {
    if (v.col(c).allFinite()) continue;
    const char* what = dynamic_cast<const RigidBody*>(&body) != nullptr
                           ? (c == 0 ? "centre" : "angular part")
                           : "node";
    throw DivergenceError(step, body.name(), quantity,
                          "is not finite (" + std::string(what) + " " + std::to_string(c) + ": " +
                              num(v(0, c)) + ", " + num(v(1, c)) + ", " + num(v(2, c)) + ")");
  }
}

double gravity_energy(const Scene& scene) {
  double e = 0.0;
  for (const auto& ff : scene.force_fields())
    if (dynamic_cast<const GravityForceField*>(ff.get()) != nullptr) e += ff->potential_energy();
  return e;
}

}  // namespace

void check_divergence(const Scene& scene, Scene::Impl& impl) {
  DivergenceState& d = impl.divergence;
  const SolverSettings& solver = scene.solver();
  if (!d.have_baseline) {
    d.have_baseline = true;
    d.kinetic0 = scene.kinetic_energy();
    d.gravity0 = gravity_energy(scene);
    d.internal0 = scene.potential_energy() - d.gravity0;
    d.checked = scene.steps_run();
    return;
  }
  if (d.checked == scene.steps_run()) return;
  d.checked = scene.steps_run();
  const std::uint64_t step = scene.steps_run() - 1;  // the step that produced this state

  for (const auto& b : scene.bodies()) {
    check_finite(*b, VecId::kX, "position", step);
    check_finite(*b, VecId::kV, "velocity", step);
    check_finite(*b, VecId::kF, "force", step);
  }

  if (solver.integrator == Integrator::kImplicitEuler && solver.cg_stall_steps > 0) {
    for (const Group& g : impl.groups) {
      GroupSolver& s = *g.solver;
      const bool stalled = s.iterations >= solver.max_iterations && !s.converged;
      s.stalled_steps = stalled ? s.stalled_steps + 1 : 0;
      if (s.stalled_steps >= solver.cg_stall_steps) {
        throw DivergenceError(step, s.name, "CG residual",
                              "stayed above the tolerance: CG ended at max_iterations=" +
                                  std::to_string(solver.max_iterations) +
                                  " without converging on " + std::to_string(s.stalled_steps) +
                                  " consecutive steps (relative residual " + num(s.residual) +
                                  ", tolerance " + num(solver.tolerance) +
                                  "; raise max_iterations or cg_stall_steps, or lower dt)");
      }
    }
  }

  if (solver.energy_factor > 0.0) {
    const double kinetic = scene.kinetic_energy();
    const double work = d.gravity0 - gravity_energy(scene);
    const double available = d.kinetic0 + d.internal0 + std::max(work, 0.0);
    const double bound = solver.energy_factor * available + kEnergyFloor;
    if (!(kinetic <= bound)) {
      // Name the body holding the most kinetic energy.
      const Body* worst = nullptr;
      double worst_e = -1.0;
      for (const auto& b : scene.bodies()) {
        const double e = b->kinetic_energy();
        if (!(e <= worst_e)) {
          worst_e = e;
          worst = b.get();
        }
      }
      throw DivergenceError(
          step, worst != nullptr ? worst->name() : std::string("scene"), "kinetic energy",
          "is " + num(worst_e) + " J (scene total " + num(kinetic) + " J), above the bound " +
              num(solver.energy_factor) + " x (initial kinetic " + num(d.kinetic0) +
              " + initial elastic and contact " + num(d.internal0) + " + work of gravity " +
              num(work) + ") J: energy is created, the integration is unstable (lower dt)");
    }
  }
}

}  // namespace detail
}  // namespace tgraph::samples
