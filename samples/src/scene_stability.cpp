// SPDX-License-Identifier: MIT
// The stability check of a scene file: Gershgorin's bound on omega_max^2 = lambda_max(M^-1 K)
// over the objects built, against explicit Euler's limit and implicit Euler's CG budget.
#include "scene_stability.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>

#include "tgraph/graph/error.hpp"

namespace tgraph::samples::detail {

void FrequencyBound::node(const std::string& object, double row, double mass) {
  if (!(mass > 0.0) || !std::isfinite(omega2_)) return;  // keep the first overflow found
  const double w2 = row / mass;
  if (!(w2 <= omega2_)) {  // also takes a NaN or infinity, reported as such
    omega2_ = w2;
    object_ = object;
    object_line_ = line_;
    row_ = row;
    mass_ = mass;
  }
}

void FrequencyBound::springs(const std::string& object, const std::vector<Spring>& springs, const Body& a,
                              const Body* b) {
  std::vector<double> ra(static_cast<std::size_t>(a.num_points()), 0.0);
  std::vector<double> rb(b != nullptr ? static_cast<std::size_t>(b->num_points()) : 0, 0.0);
  std::vector<double>& rj = b != nullptr ? rb : ra;
  for (const Spring& sp : springs) {
    ra[static_cast<std::size_t>(sp.i)] += 2.0 * sp.stiffness;
    rj[static_cast<std::size_t>(sp.j)] += 2.0 * sp.stiffness;
  }
  body_rows(object, ra, a);
  if (b != nullptr) body_rows(object, rb, *b);
}

void FrequencyBound::body_rows(const std::string& object, const std::vector<double>& rows, const Body& body) {
  for (std::size_t i = 0; i < rows.size(); ++i)
    if (rows[i] != 0.0) node(object, rows[i], point_mass(body, static_cast<Index>(i)));
}

double FrequencyBound::point_mass(const Body& body, Index i) {
  if (const auto* p = dynamic_cast<const ParticleBody*>(&body)) return p->mass(i);
  return body.total_mass();
}

std::string short_num(double v) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.3g", v);
  return buf;
}

void check_stability(Scene& scene, FrequencyBound& bound, const std::string& file,
                     bool dt_from_options, int dt_line, int last_line) {
  const CollisionSettings& c = scene.collision();
  if (c.enabled) {
    for (const auto& b : scene.bodies()) {
      if (b->surface.empty()) continue;
      double m = 1e300;
      for (Index i : b->surface) m = std::min(m, FrequencyBound::point_mass(*b, i));
      bound.node(b->name() + " (contact)", 2.0 * c.stiffness, m);
      if (c.floor) bound.node(b->name() + " (floor contact)", c.floor_stiffness, m);
    }
  }
  const SolverSettings& s = scene.solver();
  const std::string where =
      dt_from_options ? file + " with {dt}" : file + ":" + std::to_string(dt_line > 0 ? dt_line : last_line);
  const double w2 = bound.omega2();
  if (w2 == 0.0) return;
  if (!std::isfinite(w2) || w2 > 1e200)
    throw InputError(file + ":" + std::to_string(bound.object_line()), std::nullopt,
                     "object '" + bound.object() + "': " +
                         (std::isfinite(bound.row())
                              ? "stiffness " + short_num(bound.row()) + " N/m over a node mass of " +
                                    short_num(bound.mass()) + " kg gives omega_max^2 = " + short_num(w2) + " 1/s^2"
                              : std::string("the stiffness overflows double arithmetic")) +
                         ": expected omega_max^2 = stiffness/mass <= 1e200 1/s^2, which the integrators can "
                         "handle (check young=, stiffness= and density=)");
  const double omega = std::sqrt(w2);
  const double h = s.dt;
  const std::string source = "omega_max <= " + short_num(omega) + " rad/s, from object '" +
                             bound.object() + "': stiffness " + short_num(bound.row()) +
                             " N/m on a node of " + short_num(bound.mass()) + " kg";
  if (s.integrator == Integrator::kExplicitEuler) {
    if (h * omega >= 2.0)
      scene.add_warning(where + ": dt=" + short_num(h) +
                          " s may be unstable for explicit Euler, stable for dt < 2/omega_max = " +
                          short_num(2.0 / omega) + " s (" + source + ")");
    return;
  }
  // Implicit Euler is stable for any dt, but CG on M - h^2 K needs about
  // sqrt(cond)/2 ln(2/tolerance) iterations, cond <= 1 + h^2 omega_max^2.
  const double cond = 1.0 + h * h * w2;
  const double needed = 0.5 * std::sqrt(cond) * std::log(2.0 / s.tolerance);
  if (!(needed <= s.max_iterations))
    scene.add_warning(
        where + ": dt=" + short_num(h) + " s makes the implicit system stiff (condition number up to " +
        short_num(cond) + ", " + source + "): CG may need about " + short_num(needed) +
        " iterations, more than max_iterations=" + std::to_string(s.max_iterations));
}

}  // namespace tgraph::samples::detail
