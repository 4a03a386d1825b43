// SPDX-License-Identifier: MIT
// Mechanical objects: state vectors plus mass, for deformable point sets and rigid bodies.
#pragma once

#include <array>
#include <memory>
#include <string>
#include <vector>

#include "tgraph/graph/cumulative.hpp"
#include "tgraph/samples/state.hpp"

namespace tgraph::samples {

/// A simulated object: its state vectors (x, v, f and the solver's work vectors), its mass
/// and the points other components attach to (collision surface, interaction springs).
///
/// Component methods (mass, integration, point mapping) contain no capture calls; only the
/// solvers' coordination code records tasks.
class Body {
 public:
  Body(std::string name, Index columns);
  virtual ~Body() = default;
  Body(const Body&) = delete;
  Body& operator=(const Body&) = delete;

  /// Name, stable across steps (the capture's object name).
  const std::string& name() const { return name_; }
  /// Columns of every state vector.
  Index columns() const { return columns_; }
  /// State vector `id` (for a cumulative write, the temporary a live executor redirected it
  /// to: see tgraph/graph/cumulative.hpp).
  StateVec& vec(VecId id) { return accumulate(vecs_[static_cast<std::size_t>(id)]); }
  const StateVec& vec(VecId id) const { return vecs_[static_cast<std::size_t>(id)]; }

  /// out += factor * M * in.
  virtual void add_mdx(StateVec& out, const StateVec& in, double factor) const = 0;
  /// v += dt * M^-1 * f (explicit Euler's velocity update).
  virtual void add_minv(StateVec& v, const StateVec& f, double dt) const = 0;
  /// f += M * g.
  virtual void add_gravity(StateVec& f, const Vec3& g) const = 0;
  /// x += dt * v (rigid bodies integrate their orientation too).
  virtual void integrate_position(double dt) = 0;
  /// True when integrate_position also updates v (rigid bodies keep their angular momentum
  /// through the change of orientation).
  virtual bool position_update_writes_velocity() const { return false; }
  /// Kinetic energy 1/2 v^T M v.
  virtual double kinetic_energy() const = 0;
  /// Potential energy of gravity -sum m g . x (reference 0 at the origin).
  virtual double gravity_energy(const Vec3& g) const = 0;
  /// Total mass.
  virtual double total_mass() const = 0;

  /// Points components attach to (nodes of a deformable body, surface vertices of a rigid one).
  virtual Index num_points() const = 0;
  /// World position of point i.
  virtual Vec3 point(Index i) const = 0;
  /// Motion of point i for a velocity-like vector `dx` (J dx).
  virtual Vec3 point_motion(const StateVec& dx, Index i) const = 0;
  /// out += J^T F: force F applied at point i.
  virtual void add_point_force(StateVec& out, Index i, const Vec3& F) const = 0;
  /// Velocity of point i.
  Vec3 point_velocity(Index i) const { return point_motion(vec(VecId::kV), i); }

  /// Indices (into the points) of the collision surface; empty: no collision.
  std::vector<Index> surface;
  /// Proximity radius of each surface point (sphere proxies of the narrow phase).
  double contact_radius = 0.0;
  /// Surface triangles (indices into the points), for statistics and export.
  std::vector<std::array<Index, 3>> triangles;
  /// Rayleigh mass damping coefficient (1/s): damping force -alpha M v.
  double mass_damping = 0.0;
  /// Collision layer: bodies with the same non-zero layer do not collide with each other.
  int collision_layer = 0;

 protected:
  /// Sizes every state vector to `columns` zero columns.
  void resize_vectors(Index columns);

 private:
  std::string name_;
  Index columns_;
  std::array<StateVec, kVecCount> vecs_;
};

/// A deformable object: n nodes with a diagonal (lumped) mass.
class ParticleBody final : public Body {
 public:
  /// Nodes at `rest` positions, each with mass `masses[i]`.
  ParticleBody(std::string name, const StateVec& rest, std::vector<double> masses);

  /// Rest (initial) positions.
  const StateVec& rest() const { return rest_; }
  /// Mass of node i.
  double mass(Index i) const { return mass_[static_cast<std::size_t>(i)]; }
  /// True when every node has the same mass (UniformMass rather than DiagonalMass).
  bool uniform_mass() const { return uniform_; }

  void add_mdx(StateVec& out, const StateVec& in, double factor) const override;
  void add_minv(StateVec& v, const StateVec& f, double dt) const override;
  void add_gravity(StateVec& f, const Vec3& g) const override;
  void integrate_position(double dt) override;
  double kinetic_energy() const override;
  double gravity_energy(const Vec3& g) const override;
  double total_mass() const override;
  Index num_points() const override { return columns(); }
  Vec3 point(Index i) const override { return vec(VecId::kX).col(i); }
  Vec3 point_motion(const StateVec& dx, Index i) const override { return dx.col(i); }
  void add_point_force(StateVec& out, Index i, const Vec3& F) const override { out.col(i) += F; }

 private:
  StateVec rest_;
  std::vector<double> mass_;
  Eigen::ArrayXd mass_row_;      // mass_ as an array for vectorised products
  Eigen::ArrayXd inv_mass_row_;  // 1 / mass
  bool uniform_ = false;
};

/// A rigid body with 6 degrees of freedom. Column 0 of each state vector is the linear part
/// (centre of mass), column 1 the angular part; the orientation is kept as a quaternion.
class RigidBody final : public Body {
 public:
  /// Body with `mass`, body-frame inertia `inertia`, centre `center`, orientation `q`, and
  /// attachment points `local` given in the body frame (relative to the centre of mass).
  RigidBody(std::string name, double mass, const Mat3& inertia, const Vec3& center,
            const Eigen::Quaterniond& q, StateVec local);

  /// Orientation.
  const Eigen::Quaterniond& orientation() const { return q_; }
  /// Rotation matrix of the orientation.
  const Mat3& rotation() const { return rot_; }
  /// Body-frame attachment points.
  const StateVec& local_points() const { return local_; }

  void add_mdx(StateVec& out, const StateVec& in, double factor) const override;
  void add_minv(StateVec& v, const StateVec& f, double dt) const override;
  void add_gravity(StateVec& f, const Vec3& g) const override;
  /// Rotates by dt * omega, then sets omega = I_world^-1 L so that the angular momentum
  /// L = I_world omega is unchanged by the rotation (torque-free precession).
  void integrate_position(double dt) override;
  bool position_update_writes_velocity() const override { return true; }
  double kinetic_energy() const override;
  double gravity_energy(const Vec3& g) const override;
  double total_mass() const override { return mass_; }
  /// Angular momentum about the centre of mass.
  Vec3 angular_momentum() const { return inertia_world_ * vec(VecId::kV).col(1); }
  Index num_points() const override { return local_.cols(); }
  Vec3 point(Index i) const override;
  Vec3 point_motion(const StateVec& dx, Index i) const override;
  void add_point_force(StateVec& out, Index i, const Vec3& F) const override;

 private:
  void update_frame();

  double mass_;
  Mat3 inertia_body_;
  Mat3 inertia_body_inv_;
  Mat3 inertia_world_;
  Mat3 inertia_world_inv_;
  Eigen::Quaterniond q_;
  Mat3 rot_;
  StateVec local_;
};

}  // namespace tgraph::samples
