// SPDX-License-Identifier: MIT
#include "tgraph/samples/body.hpp"

#include <Eigen/LU>
#include <cmath>
#include <utility>

#include "tgraph/samples/constraint.hpp"

namespace tgraph::samples {

Body::Body(std::string name, Index columns) : name_(std::move(name)), columns_(columns) {
  resize_vectors(columns);
}

void Body::resize_vectors(Index columns) {
  columns_ = columns;
  for (StateVec& v : vecs_) v.setZero(3, columns);
}

// ---------------------------------------------------------------- ParticleBody

ParticleBody::ParticleBody(std::string name, const StateVec& rest, std::vector<double> masses)
    : Body(std::move(name), rest.cols()), rest_(rest), mass_(std::move(masses)) {
  vec(VecId::kX) = rest;
  mass_row_.resize(rest.cols());
  uniform_ = true;
  for (Index i = 0; i < rest.cols(); ++i) {
    mass_row_[i] = mass_[static_cast<std::size_t>(i)];
    if (mass_row_[i] != mass_row_[0]) uniform_ = false;
  }
  inv_mass_row_ = mass_row_.inverse();
}

void ParticleBody::add_mdx(StateVec& out, const StateVec& in, double factor) const {
  if (uniform_) {
    out.noalias() += (factor * mass_row_[0]) * in;
    return;
  }
  out.noalias() += factor * (in * mass_row_.matrix().asDiagonal());
}

void ParticleBody::add_minv(StateVec& v, const StateVec& f, double dt) const {
  v.noalias() += dt * (f * inv_mass_row_.matrix().asDiagonal());
}

void ParticleBody::add_gravity(StateVec& f, const Vec3& g) const {
  f.noalias() += g * mass_row_.matrix().transpose();
}

void ParticleBody::integrate_position(double dt) { vec(VecId::kX).noalias() += dt * vec(VecId::kV); }

double ParticleBody::kinetic_energy() const {
  const StateVec& v = vec(VecId::kV);
  return 0.5 * (v.colwise().squaredNorm().array() * mass_row_.transpose()).sum();
}

double ParticleBody::gravity_energy(const Vec3& g) const {
  const StateVec& x = vec(VecId::kX);
  return -((g.transpose() * x).array() * mass_row_.transpose()).sum();
}

double ParticleBody::total_mass() const { return mass_row_.sum(); }

// ---------------------------------------------------------------- RigidBody

RigidBody::RigidBody(std::string name, double mass, const Mat3& inertia, const Vec3& center,
                     const Eigen::Quaterniond& q, StateVec local)
    : Body(std::move(name), 2),
      mass_(mass),
      inertia_body_(inertia),
      inertia_body_inv_(inertia.inverse()),
      q_(q.normalized()),
      local_(std::move(local)) {
  vec(VecId::kX).col(0) = center;
  update_frame();
}

void RigidBody::update_frame() {
  rot_ = q_.toRotationMatrix();
  inertia_world_ = rot_ * inertia_body_ * rot_.transpose();
  inertia_world_inv_ = rot_ * inertia_body_inv_ * rot_.transpose();
}

void RigidBody::add_mdx(StateVec& out, const StateVec& in, double factor) const {
  out.col(0) += factor * mass_ * in.col(0);
  out.col(1) += factor * (inertia_world_ * in.col(1));
}

void RigidBody::add_minv(StateVec& v, const StateVec& f, double dt) const {
  v.col(0) += (dt / mass_) * f.col(0);
  v.col(1) += dt * (inertia_world_inv_ * f.col(1));
}

void RigidBody::add_gravity(StateVec& f, const Vec3& g) const { f.col(0) += mass_ * g; }

void RigidBody::integrate_position(double dt) {
  StateVec& x = vec(VecId::kX);
  const StateVec& v = vec(VecId::kV);
  x.col(0) += dt * v.col(0);
  const Vec3 w = v.col(1) * dt;
  const double angle = w.norm();
  const Vec3 momentum = inertia_world_ * v.col(1);
  if (angle > 0.0) {
    q_ = Eigen::Quaterniond(Eigen::AngleAxisd(angle, w / angle)) * q_;
    q_.normalize();
  }
  // Column 1 of x holds the accumulated rotation vector (informative only).
  x.col(1) += w;
  update_frame();
  vec(VecId::kV).col(1) = inertia_world_inv_ * momentum;
}

double RigidBody::kinetic_energy() const {
  const StateVec& v = vec(VecId::kV);
  return 0.5 * mass_ * v.col(0).squaredNorm() + 0.5 * v.col(1).dot(inertia_world_ * v.col(1));
}

double RigidBody::gravity_energy(const Vec3& g) const { return -mass_ * g.dot(vec(VecId::kX).col(0)); }

Vec3 RigidBody::point(Index i) const { return vec(VecId::kX).col(0) + rot_ * local_.col(i); }

Vec3 RigidBody::point_motion(const StateVec& dx, Index i) const {
  return dx.col(0) + Vec3(dx.col(1)).cross(rot_ * local_.col(i));
}

void RigidBody::add_point_force(StateVec& out, Index i, const Vec3& F) const {
  out.col(0) += F;
  out.col(1) += (rot_ * local_.col(i)).cross(F);
}

// ---------------------------------------------------------------- FixedConstraint

FixedConstraint::FixedConstraint(std::string name, Body* body, std::vector<Index> columns)
    : name_(std::move(name)), body_(body), columns_(std::move(columns)) {}

void FixedConstraint::project(StateVec& v) const {
  for (Index c : columns_) v.col(c).setZero();
}

}  // namespace tgraph::samples
