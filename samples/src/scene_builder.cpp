// SPDX-License-Identifier: MIT
// SceneBuilder: the scene, solver, gravity and collision directives, and what every object
// shares (names, point budget, common attributes, arrays of instances, fixed nodes, split).
#include "scene_builder.hpp"

#include <algorithm>
#include <cmath>
#include <map>

#include "tgraph/graph/error.hpp"

namespace tgraph::samples::detail {

std::unique_ptr<Scene> SceneBuilder::build(std::string_view text) {
  const int number = read_directives(text, file_, [this](Directive& d) {
    bound_.set_line(d.line());
    directive(d);
  });
  if (!scene_) Directive(file_, number, "", {}).fail("no 'scene name=...' line");
  if (scene_->bodies().empty()) Directive(file_, number, "", {}).fail("the scene has no objects");
  if (options_.dt) {
    if (!(*options_.dt > 0.0) || !std::isfinite(*options_.dt)) throw OptionError("dt", "must be > 0");
    scene_->solver().dt = *options_.dt;
  }
  if (options_.coupling) scene_->solver().coupling = *options_.coupling;
  check_stability(*scene_, bound_, file_, options_.dt.has_value(), dt_line_, number);
  return std::move(scene_);
}

void SceneBuilder::directive(Directive& d) {
  const std::string& k = d.keyword();
  if (k == "scene") {
    if (scene_) d.fail("'scene' given twice");
    scene_ = std::make_unique<Scene>(d.text("name"));
    scene_->set_default_steps(d.integer("steps", 100, 1, 1000000));
    return;
  }
  if (!scene_) d.fail("'" + k + "' before the 'scene name=...' line");
  if (k == "solver") return solver(d);
  if (k == "gravity") {
    scene_->set_gravity(d.vec3("value"));
    return;
  }
  if (k == "collision") return collision(d);
  if (k == "particles") return particles(d);
  if (k == "springs") return springs(d);
  if (k == "fem" || k == "springgrid") return grid_object(d);
  if (k == "rigid") return rigid(d);
  if (k == "chain") return chain(d);
  if (k == "cloth") return cloth(d);
  d.fail("unknown directive '" + k + "'");
}

void SceneBuilder::solver(Directive& d) {
  SolverSettings& s = scene_->solver();
  s.integrator = d.choice("integrator", "implicit", {"implicit", "explicit"}) == "explicit"
                     ? Integrator::kExplicitEuler
                     : Integrator::kImplicitEuler;
  s.coupling = d.choice("coupling", "groups", {"groups", "shared"}) == "shared" ? Coupling::kShared
                                                                                 : Coupling::kGroups;
  s.dt = d.positive("dt", 0.01);
  s.tolerance = d.positive("tolerance", 1e-5);
  s.max_iterations = static_cast<std::uint32_t>(d.integer("max_iterations", 100, 1, 100000));
  s.cg_stall_steps = static_cast<std::uint32_t>(d.integer("cg_stall_steps", 10, 0, 1000000));
  s.energy_factor = d.non_negative("energy_factor", 10.0);
  if (s.energy_factor > 0.0 && s.energy_factor < 1.0)
    d.fail("energy_factor must be 0 (off) or >= 1 (got " + d.text("energy_factor") + ")");
  dt_line_ = d.line();
}

void SceneBuilder::collision(Directive& d) {
  CollisionSettings& c = scene_->collision();
  c.enabled = true;
  c.stiffness = d.positive("stiffness", 1e4);
  c.alarm_distance = d.non_negative("alarm", 0.01);
  c.damping = d.non_negative("damping", 0.0);
  c.friction = d.non_negative("friction", 0.0);
  if (d.has("floor")) {
    c.floor = true;
    c.floor_height = d.number("floor");
  }
  c.floor_stiffness = d.positive("floor_stiffness", c.stiffness);
  c.floor_friction = d.non_negative("floor_friction", 0.0);
}

Body* SceneBuilder::body_by_name(Directive& d, const std::string& key) {
  const std::string name = d.text(key);
  Body* b = scene_->find_body(name);
  if (b == nullptr) d.fail(key + ": no object named '" + name + "' (objects must be declared first)");
  return b;
}

// Counts `n` more points (nodes, particles, rigid surface points) against
// SceneOptions::max_nodes before they are built.
void SceneBuilder::add_points(Directive& d, std::uint64_t n) {
  if (n > options_.max_nodes || points_ > options_.max_nodes - n)
    d.fail("expected at most " + std::to_string(options_.max_nodes) +
           " points (nodes, particles and rigid surface points) in the scene, this line brings "
           "it to " + std::to_string(points_ + std::min<std::uint64_t>(n, UINT64_MAX - points_)));
  points_ += n;
}

void SceneBuilder::check_new_name(Directive& d, const std::string& name) {
  if (!names_.insert(name).second) d.fail("an object named '" + name + "' already exists");
}

// Attributes every body takes: damping, velocity, collision participation.
void SceneBuilder::common(Directive& d, Body& b, double spacing) {
  b.mass_damping = d.non_negative("damping", 0.0);
  const Vec3 v = d.vec3("velocity", Vec3::Zero());
  if (dynamic_cast<RigidBody*>(&b) != nullptr)
    b.vec(VecId::kV).col(0) = v;
  else
    b.vec(VecId::kV).colwise() = v;
  const bool collide = d.integer("collide", 1, 0, 1) == 1 && scene_->collision().enabled;
  b.contact_radius = d.positive("radius", 0.5 * spacing);
  b.collision_layer = d.integer("layer", 0, 0, 1000000);
  if (!collide) b.surface.clear();
}

// The attributes every object takes: parsed on an array's first instance (`first`),
// copied to the others.
void SceneBuilder::instance_common(Directive& d, Body& b, double spacing, bool first) {
  const bool rigid = dynamic_cast<RigidBody*>(&b) != nullptr;
  if (first) {
    common(d, b, spacing);
    damping_ = b.mass_damping;
    velocity_ = b.vec(VecId::kV).cols() > 0 ? Vec3(b.vec(VecId::kV).col(0)) : Vec3::Zero();
    radius_ = b.contact_radius;
    layer_ = b.collision_layer;
    collide_ = !b.surface.empty();
    return;
  }
  b.mass_damping = damping_;
  if (rigid)
    b.vec(VecId::kV).col(0) = velocity_;
  else
    b.vec(VecId::kV).colwise() = velocity_;
  b.contact_radius = radius_;
  b.collision_layer = layer_;
  if (!collide_) b.surface.clear();
}

// split=N (or SceneOptions::split): the object's internal force field as up to N fields over
// consecutive runs of its elements or springs, each a task of its own (cumulative writes
// into the object's force vectors), so one big object no longer serialises its force and
// CG products. Run one after the other, the fields add the same terms into every node in
// the same order as the whole field (FEM: runs of whole element batches).
int SceneBuilder::split_of(Directive& d) {
  const int split = d.integer("split", 1, 1, 1024);
  if (options_.split) {
    if (*options_.split < 1 || *options_.split > 1024)
      throw OptionError("split", "must be in [1, 1024]");
    return *options_.split;
  }
  return split;
}

std::vector<Index> SceneBuilder::fixed_nodes(Directive& d, const StateVec& x, const std::string& spec) {
  std::vector<Index> out;
  if (spec.empty() || spec == "none") return out;
  if (spec == "all") {
    for (Index i = 0; i < x.cols(); ++i) out.push_back(i);
    return out;
  }
  if (spec.rfind("nodes:", 0) == 0) {
    for (double v : d.numbers("fix", 0, spec.substr(6))) {
      if (v != std::floor(v) || v < 0 || v >= static_cast<double>(x.cols()))
        d.fail("fix: node " + std::to_string(v) + " out of range [0, " + std::to_string(x.cols() - 1) + "]");
      out.push_back(static_cast<Index>(v));
    }
    return out;
  }
  static const std::map<std::string, std::pair<int, int>> kFaces = {
      {"xmin", {0, -1}}, {"xmax", {0, 1}}, {"ymin", {1, -1}}, {"ymax", {1, 1}}, {"zmin", {2, -1}}, {"zmax", {2, 1}}};
  // A face, optionally with a band depth: "ymax" or "ymax:0.03" (nodes within 3 cm).
  const std::string face = spec.substr(0, spec.find(':'));
  double band = 0.0;
  if (face.size() != spec.size()) {
    const auto v = d.numbers("fix", 1, spec.substr(face.size() + 1));
    if (!(v[0] >= 0.0)) d.fail("fix: the band depth must be >= 0");
    band = v[0];
  }
  auto it = kFaces.find(face);
  if (it == kFaces.end())
    d.fail("fix: '" + spec + "' is not none, all, nodes:i,j,..., or a face xmin, xmax, ymin, ymax, zmin, zmax (optionally face:depth)");
  const auto [axis, side] = it->second;
  const double target = side < 0 ? x.row(axis).minCoeff() : x.row(axis).maxCoeff();
  const double tol = band + 1e-9 * (1.0 + (x.row(axis).maxCoeff() - x.row(axis).minCoeff()));
  for (Index i = 0; i < x.cols(); ++i)
    if (std::abs(x(axis, i) - target) <= tol) out.push_back(i);
  return out;
}

void SceneBuilder::add_gravity(Body& b) {
  if (scene_->gravity().squaredNorm() > 0.0)
    scene_->add_force_field(std::make_unique<GravityForceField>(b.name() + ".gravity", &b, scene_->gravity()));
}

void SceneBuilder::add_fix(Body& b, std::vector<Index> cols) {
  if (!cols.empty()) scene_->add_constraint(std::make_unique<FixedConstraint>(b.name() + ".fixed", &b, std::move(cols)));
}

// Instances of an object: array=ax,ay,az spacing=dx,dy,dz, each jittered by jitter=a.
std::vector<std::pair<std::string, Vec3>> SceneBuilder::instances(Directive& d, const std::string& name, const Vec3& center) {
  const auto arr = d.int3("array", std::array<int, 3>{1, 1, 1}, 1, 4096);
  const Vec3 step = d.vec3("spacing", Vec3::Zero());
  const double jitter = d.non_negative("jitter", 0.0);
  std::vector<std::pair<std::string, Vec3>> out;
  const int count = arr[0] * arr[1] * arr[2];
  if (count > 4096) d.fail("array: at most 4096 instances");
  for (int k = 0; k < arr[2]; ++k)
    for (int j = 0; j < arr[1]; ++j)
      for (int i = 0; i < arr[0]; ++i) {
        Vec3 c = center + Vec3(i * step.x(), j * step.y(), k * step.z());
        if (jitter > 0.0) c += jitter * jitter_.vec();
        const int idx = i + arr[0] * (j + arr[1] * k);
        out.emplace_back(count == 1 ? name : name + std::to_string(idx), c);
      }
  return out;
}

}  // namespace tgraph::samples::detail
