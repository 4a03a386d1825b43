// SPDX-License-Identifier: MIT
// Gravity, springs and penalty contacts.
#include <algorithm>
#include <cmath>
#include <utility>

#include "tgraph/samples/force_field.hpp"

namespace tgraph::samples {

ForceField::ForceField(std::string name, Body* a, Body* b) : name_(std::move(name)), a_(a), b_(b) {}

void ForceField::add_dforce(VecId, VecId, double, double) {}

// ---------------------------------------------------------------- GravityForceField

GravityForceField::GravityForceField(std::string name, Body* body, const Vec3& g)
    : ForceField(std::move(name), body), g_(g) {}

void GravityForceField::add_force() { body_a()->add_gravity(body_a()->vec(VecId::kF), g_); }

double GravityForceField::potential_energy() const { return body_a()->gravity_energy(g_); }

// ---------------------------------------------------------------- SpringForceField

SpringForceField::SpringForceField(std::string name, Body* a, Body* b, std::vector<Spring> springs)
    : ForceField(std::move(name), a, b), springs_(std::move(springs)), cache_(springs_.size()) {
  particles_ = dynamic_cast<ParticleBody*>(a) != nullptr &&
               (b == nullptr || dynamic_cast<ParticleBody*>(b) != nullptr);
}

std::uint64_t SpringForceField::state_bytes() const { return cache_.size() * sizeof(Cache); }

namespace {

// Force and stiffness kernels over a body type: ParticleBody (final, inlined) or Body.
template <class BA, class BB>
void spring_forces(const std::vector<Spring>& springs, auto& cache, BA& a, BB& b) {
  StateVec& fa = a.vec(VecId::kF);
  StateVec& fb = b.vec(VecId::kF);
  for (std::size_t s = 0; s < springs.size(); ++s) {
    const Spring& sp = springs[s];
    const Vec3 d = b.point(sp.j) - a.point(sp.i);
    const double l = d.norm();
    auto& c = cache[s];
    if (l < 1e-12) {
      c.n.setZero();
      c.geo = 0.0;
      continue;
    }
    c.n = d / l;
    c.geo = std::max(0.0, 1.0 - sp.rest / l);
    const Vec3 F = (sp.stiffness * (l - sp.rest)) * c.n;
    a.add_point_force(fa, sp.i, F);
    b.add_point_force(fb, sp.j, -F);
  }
}

template <class BA, class BB>
void spring_dforces(const std::vector<Spring>& springs, const auto& cache, BA& a, BB& b, VecId df,
                    VecId dx, double k_factor) {
  StateVec& dfa = a.vec(df);
  StateVec& dfb = b.vec(df);
  const StateVec& dxa = a.vec(dx);
  const StateVec& dxb = b.vec(dx);
  for (std::size_t s = 0; s < springs.size(); ++s) {
    const Spring& sp = springs[s];
    const auto& c = cache[s];
    const Vec3 dd = b.point_motion(dxb, sp.j) - a.point_motion(dxa, sp.i);
    const double dn = c.n.dot(dd);
    const Vec3 dF = (k_factor * sp.stiffness) * (c.geo * dd + (1.0 - c.geo) * dn * c.n);
    a.add_point_force(dfa, sp.i, dF);
    b.add_point_force(dfb, sp.j, -dF);
  }
}

}  // namespace

void SpringForceField::add_force() {
  Body* a = body_a();
  Body* b = body_b() ? body_b() : body_a();
  if (particles_)
    spring_forces(springs_, cache_, static_cast<ParticleBody&>(*a), static_cast<ParticleBody&>(*b));
  else
    spring_forces(springs_, cache_, *a, *b);
}

void SpringForceField::add_dforce(VecId df, VecId dx, double k_factor, double /*b_factor*/) {
  Body* a = body_a();
  Body* b = body_b() ? body_b() : body_a();
  if (particles_)
    spring_dforces(springs_, cache_, static_cast<ParticleBody&>(*a), static_cast<ParticleBody&>(*b), df,
                   dx, k_factor);
  else
    spring_dforces(springs_, cache_, *a, *b, df, dx, k_factor);
}

double SpringForceField::potential_energy() const {
  const Body* a = body_a();
  const Body* b = body_b() ? body_b() : body_a();
  double e = 0.0;
  for (const Spring& sp : springs_) {
    const double l = (b->point(sp.j) - a->point(sp.i)).norm();
    e += 0.5 * sp.stiffness * (l - sp.rest) * (l - sp.rest);
  }
  return e;
}

// ---------------------------------------------------------------- ContactForceField

ContactForceField::ContactForceField(std::string name, Body* a, Body* b, double stiffness, double damping,
                                     double friction)
    : ForceField(std::move(name), a, b), stiffness_(stiffness), damping_(damping), friction_(friction) {}

std::uint64_t ContactForceField::state_bytes() const {
  return std::max<std::uint64_t>(1, cache_.size()) * sizeof(Cache);
}

void ContactForceField::set_pairs(std::vector<ContactPair> pairs) {
  pairs_ = std::move(pairs);
  cache_.assign(pairs_.size(), Cache{});
}

void ContactForceField::add_force() {
  Body& a = *body_a();
  Body& b = *body_b();
  const double r = a.contact_radius + b.contact_radius;
  StateVec& fa = a.vec(VecId::kF);
  StateVec& fb = b.vec(VecId::kF);
  for (std::size_t k = 0; k < pairs_.size(); ++k) {
    const Vec3 d = a.point(pairs_[k].i) - b.point(pairs_[k].j);
    const double dist = d.norm();
    Cache& c = cache_[k];
    c.active = dist < r && dist > 1e-12;
    if (!c.active) continue;
    c.n = d / dist;
    Vec3 F = (stiffness_ * (r - dist)) * c.n;
    if (damping_ > 0.0 || friction_ > 0.0) {
      const Vec3 rel = a.point_velocity(pairs_[k].i) - b.point_velocity(pairs_[k].j);
      const double vn = rel.dot(c.n);
      F -= damping_ * vn * c.n + friction_ * (rel - vn * c.n);
    }
    a.add_point_force(fa, pairs_[k].i, F);
    b.add_point_force(fb, pairs_[k].j, -F);
  }
}

void ContactForceField::add_dforce(VecId df, VecId dx, double k_factor, double b_factor) {
  Body& a = *body_a();
  Body& b = *body_b();
  StateVec& dfa = a.vec(df);
  StateVec& dfb = b.vec(df);
  const StateVec& dxa = a.vec(dx);
  const StateVec& dxb = b.vec(dx);
  const double cn = -k_factor * stiffness_ - b_factor * damping_;  // along n
  const double ct = -b_factor * friction_;                          // tangential
  for (std::size_t k = 0; k < pairs_.size(); ++k) {
    const Cache& c = cache_[k];
    if (!c.active) continue;
    const Vec3 dd = a.point_motion(dxa, pairs_[k].i) - b.point_motion(dxb, pairs_[k].j);
    const double dn = c.n.dot(dd);
    const Vec3 dF = cn * dn * c.n + ct * (dd - dn * c.n);
    a.add_point_force(dfa, pairs_[k].i, dF);
    b.add_point_force(dfb, pairs_[k].j, -dF);
  }
}

double ContactForceField::potential_energy() const {
  const Body& a = *body_a();
  const Body& b = *body_b();
  const double r = a.contact_radius + b.contact_radius;
  double e = 0.0;
  for (const ContactPair& p : pairs_) {
    const double pen = r - (a.point(p.i) - b.point(p.j)).norm();
    if (pen > 0.0) e += 0.5 * stiffness_ * pen * pen;
  }
  return e;
}

// ---------------------------------------------------------------- FloorContactForceField

FloorContactForceField::FloorContactForceField(std::string name, Body* body, double height,
                                               double stiffness, double friction_damping,
                                               double normal_damping)
    : ForceField(std::move(name), body),
      height_(height),
      stiffness_(stiffness),
      friction_damping_(friction_damping),
      normal_damping_(normal_damping) {}

std::uint64_t FloorContactForceField::state_bytes() const {
  return std::max<std::uint64_t>(1, active_.size());
}

void FloorContactForceField::set_points(std::vector<Index> points) {
  points_ = std::move(points);
  active_.assign(points_.size(), 0);
}

void FloorContactForceField::add_force() {
  Body& a = *body_a();
  StateVec& f = a.vec(VecId::kF);
  const StateVec& v = a.vec(VecId::kV);
  const double top = height_ + a.contact_radius;
  for (std::size_t k = 0; k < points_.size(); ++k) {
    const Vec3 p = a.point(points_[k]);
    const double pen = top - p.y();
    active_[k] = pen > 0.0;
    if (!active_[k]) continue;
    Vec3 F(0.0, stiffness_ * pen, 0.0);
    if (friction_damping_ > 0.0 || normal_damping_ > 0.0) {
      Vec3 vt = a.point_motion(v, points_[k]);
      F.y() -= normal_damping_ * vt.y();
      vt.y() = 0.0;
      F -= friction_damping_ * vt;
    }
    a.add_point_force(f, points_[k], F);
  }
}

void FloorContactForceField::add_dforce(VecId df, VecId dx, double k_factor, double b_factor) {
  Body& a = *body_a();
  StateVec& out = a.vec(df);
  const StateVec& in = a.vec(dx);
  const double cn = -k_factor * stiffness_ - b_factor * normal_damping_;
  const double ct = -b_factor * friction_damping_;
  for (std::size_t k = 0; k < points_.size(); ++k) {
    if (!active_[k]) continue;
    const Vec3 d = a.point_motion(in, points_[k]);
    a.add_point_force(out, points_[k], Vec3(ct * d.x(), cn * d.y(), ct * d.z()));
  }
}

double FloorContactForceField::potential_energy() const {
  const Body& a = *body_a();
  const double top = height_ + a.contact_radius;
  double e = 0.0;
  for (Index i : points_) {
    const double pen = top - a.point(i).y();
    if (pen > 0.0) e += 0.5 * stiffness_ * pen * pen;
  }
  return e;
}

}  // namespace tgraph::samples
