// SPDX-License-Identifier: MIT
// The instrumented time step: the solvers' coordination code. Every computation runs inside
// a rec.task(...) body that captures pointers to scene state (never references to locals),
// so the same code records a runnable program in capture::Mode::kDeferred.
#include <algorithm>
#include <chrono>
#include <cmath>
#include <utility>

#include "scene_impl.hpp"

namespace tgraph::samples {

using capture::Recorder;
using detail::Binding;
using detail::Group;
using detail::GroupSolver;
using detail::kNoDatum;

namespace {

constexpr AccessMode R = AccessMode::R;
constexpr AccessMode W = AccessMode::W;
constexpr AccessMode RW = AccessMode::RW;
constexpr AccessMode CW = AccessMode::CW;

// A task's accesses, built by the visitors (at most 8: an interaction's addForce).
struct AccessList {
  std::array<Access, 8> a{};
  std::size_t n = 0;
  void add(DatumId d, AccessMode m) { a[n++] = Access{d, m}; }
};

// Recorder::task takes a braced list; expand the list's length into one.
template <class F>
void issue(Recorder& rec, KindId kind, ObjectId obj, const AccessList& l, F&& body) {
  const auto& a = l.a;
  switch (l.n) {
    case 1: rec.task(kind, obj, {a[0]}, std::forward<F>(body)); return;
    case 2: rec.task(kind, obj, {a[0], a[1]}, std::forward<F>(body)); return;
    case 3: rec.task(kind, obj, {a[0], a[1], a[2]}, std::forward<F>(body)); return;
    case 4: rec.task(kind, obj, {a[0], a[1], a[2], a[3]}, std::forward<F>(body)); return;
    case 5: rec.task(kind, obj, {a[0], a[1], a[2], a[3], a[4]}, std::forward<F>(body)); return;
    case 6: rec.task(kind, obj, {a[0], a[1], a[2], a[3], a[4], a[5]}, std::forward<F>(body)); return;
    case 7:
      rec.task(kind, obj, {a[0], a[1], a[2], a[3], a[4], a[5], a[6]}, std::forward<F>(body));
      return;
    default:
      rec.task(kind, obj, {a[0], a[1], a[2], a[3], a[4], a[5], a[6], a[7]}, std::forward<F>(body));
      return;
  }
}

double dot(const StateVec& a, const StateVec& b) {
  return Eigen::Map<const Eigen::VectorXd>(a.data(), a.size())
      .dot(Eigen::Map<const Eigen::VectorXd>(b.data(), b.size()));
}

// The coordination code of one step, with the scene's ids in the recorder.
class Stepper {
 public:
  Stepper(Scene& scene, Scene::Impl& impl, Recorder& rec)
      : scene_(scene), m_(impl), b_(impl.bind), rec_(rec), h_(scene.solver().dt) {}

  ObjectId object_of(int body) const { return b_.body_object[static_cast<std::size_t>(body)]; }
  ObjectId object_of(const Body* body) const { return object_of(m_.body_index.at(body)); }

  DatumId vec(int body, VecId id) {
    DatumId& d = b_.body_vec[static_cast<std::size_t>(body)][static_cast<int>(id)];
    if (d == kNoDatum) {
      Body& bd = *scene_.bodies()[static_cast<std::size_t>(body)];
      StateVec& v = bd.vec(id);
      d = rec_.datum(bd.name() + "." + std::string(to_string(id)), object_of(body),
                     static_cast<std::uint64_t>(v.size()) * sizeof(double), v.data());
      rec_.accumulator(d, make_accumulator(v));  // force fields add through Body::vec
    }
    return d;
  }
  DatumId vec(const Body* body, VecId id) { return vec(m_.body_index.at(body), id); }

  ObjectId field_object(ForceField* ff) {
    if (!ff->is_interaction()) return object_of(ff->body_a());
    auto it = b_.field_object.find(ff->name());
    if (it != b_.field_object.end()) return it->second;
    const ObjectId o = rec_.object(ff->name());
    b_.field_object.emplace(ff->name(), o);
    b_.object_body[o] = m_.body_index.at(ff->body_a());
    return o;
  }

  DatumId field_state(ForceField* ff) {
    if (ff->state_bytes() == 0) return kNoDatum;
    auto it = b_.field_state.find(ff->name());
    if (it != b_.field_state.end()) return it->second;
    // Contact fields come and go: their state has no stable storage to point at.
    const bool stable = dynamic_cast<ContactForceField*>(ff) == nullptr &&
                        dynamic_cast<FloorContactForceField*>(ff) == nullptr;
    const DatumId d = rec_.datum(ff->name() + ".K", field_object(ff), ff->state_bytes(),
                                 stable ? ff->state_ptr() : nullptr);
    b_.field_state.emplace(ff->name(), d);
    return d;
  }

  void declare_solver(GroupSolver& s) {
    if (s.generation == b_.generation) return;
    s.generation = b_.generation;
    s.object = rec_.object(s.name);
    b_.object_body[s.object] = s.first_body;
    auto scalar = [&](const char* what, void* ptr, std::uint64_t bytes) {
      return rec_.datum(s.name + "." + what, kNoObject, bytes, ptr);
    };
    s.d_rho = scalar("rho", &s.rho, sizeof(double));
    s.d_rho_new = scalar("rho_new", &s.rho_new, sizeof(double));
    s.d_den = scalar("den", &s.den, sizeof(double));
    rec_.accumulator(s.d_rho, make_accumulator(s.rho));  // the dot products' partial sums
    rec_.accumulator(s.d_rho_new, make_accumulator(s.rho_new));
    rec_.accumulator(s.d_den, make_accumulator(s.den));
    s.d_beta = scalar("beta", &s.beta, sizeof(double));
    s.d_b2 = scalar("b2", &s.b2, sizeof(double));
    s.d_cond = scalar("converged", &s.converged, sizeof(bool));
  }

  // Resolves the ids of a group's fields once per step (not once per CG iteration); the
  // stiffness state is a datum only for the implicit solver (explicit steps never read it).
  void prepare(Group& g, bool with_state) {
    g.refs.clear();
    for (ForceField* ff : g.fields) {
      detail::FieldRef r;
      r.ff = ff;
      r.object = field_object(ff);
      r.state = with_state ? field_state(ff) : kNoDatum;
      r.body_a = m_.body_index.at(ff->body_a());
      r.body_b = ff->body_b() ? m_.body_index.at(ff->body_b()) : -1;
      g.refs.push_back(r);
    }
  }

  // addForce of one field: reads x (and v) of its bodies, accumulates into their f; with
  // `state`, also writes the stiffness state that addDForce reads (implicit solver only).
  void add_force(const detail::FieldRef& r, bool state) {
    ForceField* ff = r.ff;
    AccessList acc;
    for (int bd : {r.body_a, r.body_b}) {
      if (bd < 0) continue;
      if (ff->reads_position()) acc.add(vec(bd, VecId::kX), R);
      if (ff->reads_velocity()) acc.add(vec(bd, VecId::kV), R);
    }
    for (int bd : {r.body_a, r.body_b})
      if (bd >= 0) acc.add(vec(bd, VecId::kF), CW);
    if (state && r.state != kNoDatum) acc.add(r.state, RW);
    issue(rec_, b_.add_force, r.object, acc, [ff] { ff->add_force(); });
  }

  // addDForce of one field: df += (k K + kb B) dx.
  void add_dforce(const detail::FieldRef& r, VecId df, VecId dx, double k, double kb) {
    ForceField* ff = r.ff;
    AccessList acc;
    for (int bd : {r.body_a, r.body_b})
      if (bd >= 0) acc.add(vec(bd, dx), R);
    if (r.state != kNoDatum) acc.add(r.state, R);
    for (int bd : {r.body_a, r.body_b})
      if (bd >= 0) acc.add(vec(bd, df), CW);
    issue(rec_, b_.add_dforce, r.object, acc, [ff, df, dx, k, kb] { ff->add_dforce(df, dx, k, kb); });
  }

  void project(FixedConstraint* c, VecId id) {
    rec_.task(b_.project, object_of(c->body()), {{vec(c->body(), id), RW}},
              [c, id] { c->project(c->body()->vec(id)); });
  }

  Body* body(int i) const { return scene_.bodies()[static_cast<std::size_t>(i)].get(); }

  void reset_forces(const Group& g) {
    for (int i : g.bodies) {
      Body* bd = body(i);
      rec_.task(b_.reset_force, object_of(i), {{vec(i, VecId::kF), W}},
                [bd] { bd->vec(VecId::kF).setZero(); });
    }
  }

  // Symplectic Euler (the paper's Algorithm 1 and Figure 2).
  void explicit_euler(Group& g) {
    prepare(g, false);
    const double h = h_;
    reset_forces(g);
    for (const detail::FieldRef& r : g.refs) add_force(r, false);
    for (FixedConstraint* c : g.constraints) project(c, VecId::kF);
    for (int i : g.bodies) {
      Body* bd = body(i);
      rec_.task(b_.update_velocity, object_of(i), {{vec(i, VecId::kF), R}, {vec(i, VecId::kV), RW}},
                [bd, h] {
                  bd->add_minv(bd->vec(VecId::kV), bd->vec(VecId::kF), h);
                  if (bd->mass_damping > 0.0) bd->vec(VecId::kV) /= 1.0 + h * bd->mass_damping;
                });
    }
    update_positions(g);
  }

  void update_positions(const Group& g) {
    const double h = h_;
    for (int i : g.bodies) {
      Body* bd = body(i);
      rec_.task(b_.update_position, object_of(i),
                {{vec(i, VecId::kV), bd->position_update_writes_velocity() ? RW : R}, {vec(i, VecId::kX), RW}},
                [bd, h] { bd->integrate_position(h); });
    }
  }

  // Backward Euler: (M (1 + h alpha) - h B - h^2 K) dv = h (f - alpha M v + h K v), solved
  // by conjugate gradient as a dynamic loop (paper section 3.3); v += dv; x += h v.
  // Recorded in four parts, each for every group before the next part (advance()), so that
  // a processor waiting for the end of one group's force assembly has the other groups'
  // assembly before it in program order rather than after that group's loop.
  // Part 1: forces and their derivative on v.
  void implicit_assemble(Group& g) {
    prepare(g, true);
    declare_solver(*g.solver);
    const double h = h_;
    reset_forces(g);
    for (const detail::FieldRef& r : g.refs) add_force(r, true);
    for (const detail::FieldRef& r : g.refs)
      if (r.ff->has_stiffness()) add_dforce(r, VecId::kF, VecId::kV, h, 0.0);
  }

  // Part 2: the right-hand side and the first residual.
  void implicit_rhs(Group& g) {
    GroupSolver* s = g.solver;
    const double h = h_;
    rec_.task(b_.cg_init, s->object,
              {{s->d_rho, W}, {s->d_den, W}, {s->d_rho_new, W}, {s->d_beta, W}}, [s] {
                s->rho = s->den = s->rho_new = s->beta = 0.0;
                s->iterations = 0;
              });
    for (int i : g.bodies) {
      Body* bd = body(i);
      rec_.task(b_.compute_rhs, object_of(i),
                {{vec(i, VecId::kF), R}, {vec(i, VecId::kV), R}, {vec(i, VecId::kR), W},
                 {vec(i, VecId::kDv), W}, {vec(i, VecId::kP), W}},
                [bd, h] {
                  StateVec& r = bd->vec(VecId::kR);
                  r = h * bd->vec(VecId::kF);
                  if (bd->mass_damping > 0.0) bd->add_mdx(r, bd->vec(VecId::kV), -h * bd->mass_damping);
                  bd->vec(VecId::kDv).setZero();
                  bd->vec(VecId::kP).setZero();
                });
    }
    for (FixedConstraint* c : g.constraints) project(c, VecId::kR);
    for (int i : g.bodies) {
      Body* bd = body(i);
      rec_.task(b_.dot, object_of(i), {{vec(i, VecId::kR), R}, {s->d_rho, CW}},
                [bd, s] { accumulate(s->rho) += dot(bd->vec(VecId::kR), bd->vec(VecId::kR)); });
    }
    rec_.task(b_.cg_start, s->object, {{s->d_rho, R}, {s->d_b2, W}, {s->d_cond, W}}, [s] {
      s->b2 = s->rho;
      s->converged = false;
    });
  }

  // Part 3: the conjugate gradient iterations.
  void implicit_solve(Group& g) {
    GroupSolver* s = g.solver;
    const double h = h_;
    const double tol2 = scene_.solver().tolerance * scene_.solver().tolerance;
    const LoopId loop = rec_.begin_loop(s->d_cond, scene_.solver().max_iterations);
    do {
      for (int i : g.bodies) {
        Body* bd = body(i);
        rec_.task(b_.cg_direction, object_of(i),
                  {{vec(i, VecId::kR), R}, {s->d_beta, R}, {vec(i, VecId::kP), RW}}, [bd, s] {
                    StateVec& p = bd->vec(VecId::kP);
                    p = bd->vec(VecId::kR) + s->beta * p;
                  });
      }
      for (int i : g.bodies) {
        Body* bd = body(i);
        rec_.task(b_.add_mdx, object_of(i), {{vec(i, VecId::kP), R}, {vec(i, VecId::kQ), W}},
                  [bd, h] {
                    StateVec& q = bd->vec(VecId::kQ);
                    q.setZero();
                    bd->add_mdx(q, bd->vec(VecId::kP), 1.0 + h * bd->mass_damping);
                  });
      }
      for (const detail::FieldRef& r : g.refs)
        if (r.ff->has_stiffness()) add_dforce(r, VecId::kQ, VecId::kP, -h * h, -h);
      for (FixedConstraint* c : g.constraints) project(c, VecId::kQ);
      for (int i : g.bodies) {
        Body* bd = body(i);
        rec_.task(b_.dot, object_of(i),
                  {{vec(i, VecId::kP), R}, {vec(i, VecId::kQ), R}, {s->d_den, CW}},
                  [bd, s] { accumulate(s->den) += dot(bd->vec(VecId::kP), bd->vec(VecId::kQ)); });
      }
      for (int i : g.bodies) {
        Body* bd = body(i);
        rec_.task(b_.cg_update, object_of(i),
                  {{s->d_den, R}, {s->d_rho, R}, {vec(i, VecId::kP), R}, {vec(i, VecId::kQ), R},
                   {vec(i, VecId::kDv), RW}, {vec(i, VecId::kR), RW}, {s->d_rho_new, CW}},
                  [bd, s] {
                    const double alpha = s->den > 0.0 ? s->rho / s->den : 0.0;
                    bd->vec(VecId::kDv).noalias() += alpha * bd->vec(VecId::kP);
                    StateVec& r = bd->vec(VecId::kR);
                    r.noalias() -= alpha * bd->vec(VecId::kQ);
                    accumulate(s->rho_new) += dot(r, r);
                  });
      }
      rec_.task(b_.cg_scalars, s->object,
                {{s->d_rho_new, RW}, {s->d_rho, RW}, {s->d_b2, R}, {s->d_beta, W}, {s->d_den, W},
                 {s->d_cond, W}},
                [s, tol2] {
                  s->beta = s->rho > 0.0 ? s->rho_new / s->rho : 0.0;
                  s->rho = s->rho_new;
                  s->rho_new = 0.0;
                  s->den = 0.0;
                  ++s->iterations;
                  s->residual = s->b2 > 0.0 ? std::sqrt(s->rho / s->b2) : 0.0;
                  s->converged = s->rho <= tol2 * s->b2;
                });
    } while (!rec_.conditional_break(loop, [s] { return s->converged; }));
    rec_.end_loop(loop);
  }

  // Part 4: v += dv; x += h v.
  void implicit_update(Group& g) {
    for (int i : g.bodies) {
      Body* bd = body(i);
      rec_.task(b_.update_velocity, object_of(i), {{vec(i, VecId::kDv), R}, {vec(i, VecId::kV), RW}},
                [bd] { bd->vec(VecId::kV) += bd->vec(VecId::kDv); });
    }
    update_positions(g);
  }

 private:
  Scene& scene_;
  Scene::Impl& m_;
  Binding& b_;
  Recorder& rec_;
  double h_;
};
}  // namespace

void Scene::step(Recorder& rec) { advance(rec, false); }

bool Scene::step_if_changed(Recorder& rec) { return advance(rec, true); }

bool Scene::advance(Recorder& rec, bool allow_reuse) {
  finalize();
  // From here to the first task: the step's serial work outside the graph (StepGraph::host_ns).
  auto host_start = std::chrono::steady_clock::now();
  detail::check_divergence(*this, *impl_);  // what the last step left (deferred: ran since)
  Impl& m = *impl_;
  Binding& b = m.bind;
  const std::size_t n = bodies_.size();

  // Ids of this recorder (declared once per recorder; see the class comment).
  if (b.rec != &rec) {
    b = Binding{};
    b.rec = &rec;
    b.generation = m.next_generation++;
    b.reset_force = rec.kind("resetForce");
    b.add_force = rec.kind("addForce");
    b.add_dforce = rec.kind("addDForce");
    b.project = rec.kind("projectResponse");
    b.update_velocity = rec.kind("updateVelocity");
    b.update_position = rec.kind("updatePosition");
    b.compute_rhs = rec.kind("computeRhs");
    b.dot = rec.kind("dotProduct");
    b.cg_init = rec.kind("cgInit");
    b.cg_start = rec.kind("cgStart");
    b.cg_direction = rec.kind("cgDirection");
    b.add_mdx = rec.kind("addMDx");
    b.cg_update = rec.kind("cgUpdate");
    b.cg_scalars = rec.kind("cgScalars");
    b.update_proxy = rec.kind("updateProxy");
    b.collide_pair = rec.kind("collidePair");
    b.collide_floor = rec.kind("collideFloor");
    b.body_object.resize(n);
    b.body_vec.assign(n, {});
    for (auto& ids : b.body_vec) ids.fill(kNoDatum);
    for (std::size_t i = 0; i < n; ++i) {
      b.body_object[i] = rec.object(bodies_[i]->name());
      b.object_body[b.body_object[i]] = static_cast<int>(i);
    }
    // Declaring ids is once per recorder, not this step's work.
    host_start = std::chrono::steady_clock::now();
  }

  // Collision detection, host part: the contact sets the last step's tasks found, merged.
  if (collision_.enabled) detail::detect_collisions(*this, m);

  // Collision groups: connected components of the interactions.
  const std::vector<ForceField*> interactions = detail::form_groups(*this, m);

  // The detection tasks this step records for the next one.
  const bool detect_in_graph = collision_.enabled && collision_.in_graph;
  if (detect_in_graph) detail::plan_detection(*this, m);

  // The shape of this step: every interaction field, then each body's group, then the
  // narrow-phase tasks (their slots).
  std::vector<const void*> shape(interactions.begin(), interactions.end());
  shape.push_back(nullptr);
  for (std::size_t i = 0; i < n; ++i)
    shape.push_back(m.groups[static_cast<std::size_t>(m.body_group[i])].solver);
  if (detect_in_graph) {
    shape.push_back(nullptr);
    for (const auto& key : m.collide.planned_pairs) shape.push_back(m.collide.pair_slots.at(key).get());
    shape.push_back(nullptr);
    for (int f : m.collide.planned_floors) shape.push_back(m.collide.floor_slots[static_cast<std::size_t>(f)].get());
  }
  const bool reuse = allow_reuse && b.rec == &rec && shape == m.recorded_shape;
  if (!reuse) m.recorded_shape = std::move(shape);
  stats_ = StepStats{};
  stats_.groups = static_cast<std::uint32_t>(m.groups.size());
  stats_.interactions = static_cast<std::uint32_t>(interactions.size());
  stats_.contact_fields = static_cast<std::uint32_t>(m.contacts.size());
  for (const auto& [key, cf] : m.contacts) stats_.contact_pairs += cf->pairs().size();
  if (detect_in_graph)
    stats_.narrow_tasks = static_cast<std::uint32_t>(m.collide.planned_pairs.size() + m.collide.planned_floors.size());
  stats_.host_narrow = m.collide.host_narrow;
  time_ += solver_.dt;
  ++steps_run_;
  if (reuse) return false;

  rec.begin_step(static_cast<std::uint64_t>(std::chrono::duration_cast<std::chrono::nanoseconds>(
                                             std::chrono::steady_clock::now() - host_start)
                                             .count()));
  Stepper stepper(*this, m, rec);
  // Declare everything this step touches before the contact set names the objects.
  std::vector<Contact> contact_set;
  for (ForceField* ff : interactions) {
    stepper.field_object(ff);
    ObjectId a = stepper.object_of(ff->body_a());
    ObjectId c = stepper.object_of(ff->body_b());
    if (a > c) std::swap(a, c);
    contact_set.push_back({a, c});
  }
  std::sort(contact_set.begin(), contact_set.end());
  contact_set.erase(std::unique(contact_set.begin(), contact_set.end()), contact_set.end());
  if (solver_.integrator == Integrator::kImplicitEuler)
    for (Group& g : m.groups) stepper.declare_solver(*g.solver);
  if (detect_in_graph) detail::declare_detection(*this, m, rec);
  ObjectId max_object = 0;
  for (const auto& [obj, body] : b.object_body) max_object = std::max(max_object, obj);
  std::vector<std::uint32_t> group_of(static_cast<std::size_t>(max_object) + 1, 0);
  for (const auto& [obj, body] : b.object_body)
    group_of[obj] = static_cast<std::uint32_t>(m.body_group[static_cast<std::size_t>(body)]);
  rec.set_contacts(std::move(contact_set), std::move(group_of));

  switch (solver_.integrator) {
    case Integrator::kExplicitEuler:
      for (Group& g : m.groups) stepper.explicit_euler(g);
      break;
    case Integrator::kImplicitEuler:
      for (Group& g : m.groups) stepper.implicit_assemble(g);
      for (Group& g : m.groups) stepper.implicit_rhs(g);
      for (Group& g : m.groups) stepper.implicit_solve(g);
      for (Group& g : m.groups) stepper.implicit_update(g);
      break;
  }
  if (detect_in_graph) detail::record_detection(*this, m, rec, [&stepper](int i) { return stepper.vec(i, VecId::kX); });
  if (rec.mode() != capture::Mode::kDeferred) detail::check_divergence(*this, m);
  return true;
}

}  // namespace tgraph::samples
