// SPDX-License-Identifier: MIT
// Time integration settings (the coordination code itself lives in the scene's step).
#pragma once

#include <cstdint>
#include <string_view>

namespace tgraph::samples {

/// Time integration scheme.
enum class Integrator : std::uint8_t {
  kExplicitEuler = 0,  ///< symplectic Euler: v += h M^-1 f, x += h v
  kImplicitEuler = 1,  ///< backward Euler, (M - h^2 K) dv = h (f + h K v), matrix-free CG
};
/// "explicit" or "implicit".
std::string_view to_string(Integrator integrator);

/// Which objects share one solver instance (and hence one CG loop).
enum class Coupling : std::uint8_t {
  kGroups = 0,  ///< one solver per collision group (connected components of interactions)
  kShared = 1,  ///< one solver for the whole scene
};
/// "groups" or "shared".
std::string_view to_string(Coupling coupling);

/// Settings of the time integration.
struct SolverSettings {
  Integrator integrator = Integrator::kImplicitEuler;
  Coupling coupling = Coupling::kGroups;
  double dt = 0.01;                    ///< time step (s)
  double tolerance = 1e-5;             ///< CG stops when |r| <= tolerance |b|
  std::uint32_t max_iterations = 100;  ///< CG iteration cap
  /// Divergence check: a CG solve ending at max_iterations without converging on this many
  /// consecutive steps stops the run (0: never).
  std::uint32_t cg_stall_steps = 10;
  /// Divergence check: kinetic energy above energy_factor x (initial kinetic + initial
  /// internal potential energy + work done by gravity since) stops the run (0: never).
  double energy_factor = 10.0;
};

}  // namespace tgraph::samples
