// SPDX-License-Identifier: MIT
// A scene's bodies, force fields and constraints, its collision groups, and its energies.
#include <algorithm>
#include <numeric>
#include <utility>

#include "scene_impl.hpp"
#include "tgraph/graph/error.hpp"

namespace tgraph::samples {

std::string_view to_string(Integrator integrator) {
  switch (integrator) {
    case Integrator::kExplicitEuler: return "explicit";
    case Integrator::kImplicitEuler: return "implicit";
  }
  return "?";
}

std::string_view to_string(Coupling coupling) {
  switch (coupling) {
    case Coupling::kGroups: return "groups";
    case Coupling::kShared: return "shared";
  }
  return "?";
}

namespace {

int find_root(std::vector<int>& parent, int i) {
  while (parent[static_cast<std::size_t>(i)] != i) {
    parent[static_cast<std::size_t>(i)] = parent[static_cast<std::size_t>(parent[static_cast<std::size_t>(i)])];
    i = parent[static_cast<std::size_t>(i)];
  }
  return i;
}

}  // namespace

Scene::Scene(std::string name) : name_(std::move(name)), impl_(std::make_unique<Impl>()) {}
Scene::~Scene() = default;

Body& Scene::add_body(std::unique_ptr<Body> body) {
  if (impl_->finalized) throw UsageError("scene " + name_ + ": bodies must be added before the first step");
  bodies_.push_back(std::move(body));
  return *bodies_.back();
}

ForceField& Scene::add_force_field(std::unique_ptr<ForceField> field) {
  if (impl_->finalized) throw UsageError("scene " + name_ + ": fields must be added before the first step");
  fields_.push_back(std::move(field));
  return *fields_.back();
}

FixedConstraint& Scene::add_constraint(std::unique_ptr<FixedConstraint> constraint) {
  if (impl_->finalized) throw UsageError("scene " + name_ + ": constraints must be added before the first step");
  constraints_.push_back(std::move(constraint));
  return *constraints_.back();
}

Body* Scene::find_body(std::string_view name) const {
  for (const auto& b : bodies_)
    if (b->name() == name) return b.get();
  return nullptr;
}

void Scene::finalize() {
  Impl& m = *impl_;
  if (m.finalized) return;
  m.finalized = true;
  const std::size_t n = bodies_.size();
  for (std::size_t i = 0; i < n; ++i) m.body_index.emplace(bodies_[i].get(), static_cast<int>(i));
  m.body_fields.assign(n, {});
  m.body_constraints.assign(n, {});
  for (const auto& ff : fields_) {
    if (ff->is_interaction())
      m.interactions.push_back(ff.get());
    else
      m.body_fields[static_cast<std::size_t>(m.body_index.at(ff->body_a()))].push_back(ff.get());
  }
  for (const auto& c : constraints_)
    m.body_constraints[static_cast<std::size_t>(m.body_index.at(c->body()))].push_back(c.get());
  m.immobile.assign(n, 0);
  for (std::size_t i = 0; i < n; ++i) {
    std::vector<char> fixed(static_cast<std::size_t>(bodies_[i]->columns()), 0);
    for (const FixedConstraint* c : m.body_constraints[i])
      for (Index col : c->columns()) fixed[static_cast<std::size_t>(col)] = 1;
    m.immobile[i] = std::all_of(fixed.begin(), fixed.end(), [](char f) { return f != 0; }) ? 1 : 0;
  }
  if (collision_.enabled && collision_.floor) {
    for (std::size_t i = 0; i < n; ++i) {
      Body* b = bodies_[i].get();
      if (b->surface.empty()) continue;
      m.floors.push_back(std::make_unique<FloorContactForceField>(
          b->name() + ".floor", b, collision_.floor_height, collision_.floor_stiffness,
          collision_.floor_friction, collision_.damping));
      m.body_fields[i].push_back(m.floors.back().get());
    }
  }
}
std::vector<ForceField*> detail::form_groups(const Scene& scene, Scene::Impl& m) {
  std::vector<ForceField*> interactions = m.interactions;
  for (auto& [key, cf] : m.contacts) interactions.push_back(cf.get());
  const std::size_t n = scene.bodies().size();
  std::vector<int> parent(n);
  std::iota(parent.begin(), parent.end(), 0);
  for (ForceField* ff : interactions) {
    const int a = find_root(parent, m.body_index.at(ff->body_a()));
    const int c = find_root(parent, m.body_index.at(ff->body_b()));
    if (a != c) parent[static_cast<std::size_t>(std::max(a, c))] = std::min(a, c);
  }
  if (scene.solver().coupling == Coupling::kShared)
    for (std::size_t i = 0; i < n; ++i) parent[i] = 0;
  m.groups.clear();
  m.body_group.assign(n, -1);
  for (std::size_t i = 0; i < n; ++i) {
    const int root = find_root(parent, static_cast<int>(i));
    if (m.body_group[static_cast<std::size_t>(root)] < 0) {
      m.body_group[static_cast<std::size_t>(root)] = static_cast<int>(m.groups.size());
      m.groups.emplace_back();
    }
    const int gi = m.body_group[static_cast<std::size_t>(root)];
    m.body_group[i] = gi;
    Group& g = m.groups[static_cast<std::size_t>(gi)];
    g.bodies.push_back(static_cast<int>(i));
    for (ForceField* ff : m.body_fields[i]) g.fields.push_back(ff);
    for (FixedConstraint* c : m.body_constraints[i]) g.constraints.push_back(c);
  }
  for (ForceField* ff : interactions)
    m.groups[static_cast<std::size_t>(m.body_group[static_cast<std::size_t>(m.body_index.at(ff->body_a()))])]
        .fields.push_back(ff);
  for (Group& g : m.groups) {
    const std::string solver_name = scene.solver().coupling == Coupling::kShared
                                        ? std::string("solver")
                                        : "solver[" + scene.bodies()[static_cast<std::size_t>(g.bodies[0])]->name() + "]";
    auto& slot = m.solvers[solver_name];
    if (!slot) {
      slot = std::make_unique<GroupSolver>();
      slot->name = solver_name;
      slot->first_body = g.bodies[0];
    }
    g.solver = slot.get();
  }
  return interactions;
}

StepStats Scene::last_stats() const {
  StepStats s = stats_;
  if (solver_.integrator == Integrator::kImplicitEuler) {
    for (const detail::Group& g : impl_->groups) {
      s.cg_iterations = std::max(s.cg_iterations, g.solver->iterations);
      s.cg_residual = std::max(s.cg_residual, g.solver->residual);
    }
  }
  return s;
}

std::vector<const ContactForceField*> Scene::contact_fields() const {
  std::vector<const ContactForceField*> out;
  for (const auto& [key, cf] : impl_->contacts) out.push_back(cf.get());
  return out;
}

std::vector<const FloorContactForceField*> Scene::floor_fields() const {
  std::vector<const FloorContactForceField*> out;
  for (const auto& ff : impl_->floors) out.push_back(ff.get());
  return out;
}

double Scene::kinetic_energy() const {
  double e = 0.0;
  for (const auto& b : bodies_) e += b->kinetic_energy();
  return e;
}

double Scene::potential_energy() const {
  double e = 0.0;
  for (const auto& ff : fields_) e += ff->potential_energy();
  for (const auto& ff : impl_->floors) e += ff->potential_energy();
  for (const auto& [key, cf] : impl_->contacts) e += cf->potential_energy();
  return e;
}

std::uint64_t Scene::surface_triangles() const {
  std::uint64_t t = 0;
  for (const auto& b : bodies_) t += b->triangles.size();
  return t;
}

}  // namespace tgraph::samples
