// SPDX-License-Identifier: MIT
// The stability check of a scene file (scene_stability.cpp): a bound on the scene's highest
// natural frequency against the integrator and its time step.
#pragma once

#include <string>
#include <vector>

#include "tgraph/samples/scene.hpp"

namespace tgraph::samples::detail {

// Upper bound on the highest natural frequency of the scene, omega_max^2 = lambda_max(M^-1 K),
// by Gershgorin's theorem on each node's row: omega^2 <= (sum over the node's row of |K_ij|)
// / m_i. A spring of stiffness k adds k to the diagonal and -k (projected) off it, so 2 k
// per node it touches; an FEM element adds the largest absolute row sum of its 24 x 24
// stiffness matrix; a contact or floor point adds its penalty stiffness (twice the stiffness:
// one pair, both ends). The stiffest node names the object in the messages.
class FrequencyBound {
 public:
  // One node: `row` = sum of |K_ij| over its row, `mass` its mass.
  void node(const std::string& object, double row, double mass);
  // Springs between nodes of `a` (and `b`, or `a` again when null).
  void springs(const std::string& object, const std::vector<Spring>& springs, const Body& a,
               const Body* b);
  void body_rows(const std::string& object, const std::vector<double>& rows, const Body& body);
  // Mass a force at point i moves: the node's mass, or a rigid body's whole mass.
  static double point_mass(const Body& body, Index i);
  // Line of the directive being built (named in messages).
  void set_line(int line) { line_ = line; }
  int object_line() const { return object_line_; }
  double omega2() const { return omega2_; }
  const std::string& object() const { return object_; }
  double row() const { return row_; }
  double mass() const { return mass_; }

 private:
  double omega2_ = 0.0;
  std::string object_;
  int line_ = 0;
  int object_line_ = 0;
  double row_ = 0.0;
  double mass_ = 0.0;
};

/// "%.3g" of `v` (numbers in the stability messages).
std::string short_num(double v);

/// Settings the integrator cannot handle: a stiffness that overflows is refused (InputError
/// at the stiffest object's line of `file`); a time step above the explicit stability limit,
/// or one that leaves CG too few iterations, is a warning on `scene` (the divergence checks of
/// Scene::step stop a run that does blow up). `bound` holds the objects; the contacts are
/// added here. Warnings name `file` "with {dt}" (the field SceneOptions::dt, which a front end
/// writes in its own words: name_fields) when the time step came from the options, else the
/// solver line `dt_line` (or `last_line` without one).
void check_stability(Scene& scene, FrequencyBound& bound, const std::string& file,
                     bool dt_from_options, int dt_line, int last_line);

}  // namespace tgraph::samples::detail
