// SPDX-License-Identifier: MIT
// Scene files (format: samples/scenes/README.md) and the built-in scenes.
#include <algorithm>
#include <charconv>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <map>
#include <random>
#include <set>
#include <sstream>
#include <utility>

#include "builders.hpp"
#include "tgraph/graph/error.hpp"
#include "tgraph/samples/scene.hpp"

namespace tgraph::samples {

namespace detail {
/// Built-in scene files: {name, text}, generated from samples/scenes/*.scene.
struct BuiltinScene {
  const char* name;
  const char* text;
};
extern const BuiltinScene kBuiltinScenes[];
extern const std::size_t kBuiltinSceneCount;
}  // namespace detail

namespace {

using detail::HexMesh;
using detail::Shape;

// Up to this many particles, the contact radius comes from the exact closest pair.
constexpr Index kExactSpacingPoints = 2048;

// Deterministic uniform numbers in [-1, 1) from the scene seed (independent of the
// standard library's distribution implementations).
class Jitter {
 public:
  explicit Jitter(std::uint64_t seed) : gen_(seed) {}
  double uniform() { return static_cast<double>(gen_() >> 11) * (2.0 / 9007199254740992.0) - 1.0; }
  Vec3 vec() {
    const double x = uniform(), y = uniform(), z = uniform();
    return {x, y, z};
  }

 private:
  std::mt19937_64 gen_;
};

// One line of a scene file: a keyword and key=value attributes.
class Directive {
 public:
  Directive(std::string file, int line, std::string keyword, std::map<std::string, std::string> attrs)
      : file_(std::move(file)), line_(line), keyword_(std::move(keyword)), attrs_(std::move(attrs)) {}

  const std::string& keyword() const { return keyword_; }
  int line() const { return line_; }

  [[noreturn]] void fail(const std::string& what) const {
    throw InputError(file_ + ":" + std::to_string(line_), std::nullopt, what);
  }

  bool has(const std::string& key) const { return attrs_.count(key) != 0; }

  std::string text(const std::string& key, std::optional<std::string> def = std::nullopt) {
    auto it = attrs_.find(key);
    if (it == attrs_.end()) {
      if (!def) fail("'" + keyword_ + "' needs " + key + "=...");
      return *def;
    }
    used_.insert(key);
    return it->second;
  }

  double number(const std::string& key, std::optional<double> def = std::nullopt) {
    if (!has(key)) {
      if (!def) fail("'" + keyword_ + "' needs " + key + "=<number>");
      return *def;
    }
    return parse_number(key, text(key));
  }

  double positive(const std::string& key, std::optional<double> def = std::nullopt) {
    const double v = number(key, def);
    if (!(v > 0.0)) fail(key + " must be > 0 (got " + text(key, std::to_string(v)) + ")");
    return v;
  }

  double non_negative(const std::string& key, std::optional<double> def = std::nullopt) {
    const double v = number(key, def);
    if (!(v >= 0.0)) fail(key + " must be >= 0");
    return v;
  }

  int integer(const std::string& key, std::optional<int> def, int lo, int hi) {
    if (!has(key)) {
      if (!def) fail("'" + keyword_ + "' needs " + key + "=<integer>");
      return *def;
    }
    const std::string s = text(key);
    int v = 0;
    auto [p, ec] = std::from_chars(s.data(), s.data() + s.size(), v);
    if (ec != std::errc() || p != s.data() + s.size()) fail(key + ": '" + s + "' is not an integer");
    if (v < lo || v > hi) fail(key + " must be in [" + std::to_string(lo) + ", " + std::to_string(hi) + "]");
    return v;
  }

  std::vector<double> numbers(const std::string& key, std::size_t count, const std::string& s) {
    std::vector<double> out;
    std::size_t start = 0;
    while (start <= s.size()) {
      const std::size_t comma = s.find(',', start);
      const std::string part = s.substr(start, comma == std::string::npos ? std::string::npos : comma - start);
      out.push_back(parse_number(key, part));
      if (comma == std::string::npos) break;
      start = comma + 1;
    }
    if (count != 0 && out.size() != count)
      fail(key + ": expected " + std::to_string(count) + " comma-separated numbers, got " + std::to_string(out.size()));
    return out;
  }

  Vec3 vec3(const std::string& key, std::optional<Vec3> def = std::nullopt) {
    if (!has(key)) {
      if (!def) fail("'" + keyword_ + "' needs " + key + "=x,y,z");
      return *def;
    }
    const auto v = numbers(key, 3, text(key));
    return {v[0], v[1], v[2]};
  }

  std::array<int, 3> int3(const std::string& key, std::optional<std::array<int, 3>> def, int lo, int hi) {
    if (!has(key)) {
      if (!def) fail("'" + keyword_ + "' needs " + key + "=a,b,c");
      return *def;
    }
    const auto v = numbers(key, 3, text(key));
    std::array<int, 3> out{};
    for (std::size_t i = 0; i < 3; ++i) {
      if (v[i] != std::floor(v[i]) || v[i] < lo || v[i] > hi)
        fail(key + ": each value must be an integer in [" + std::to_string(lo) + ", " + std::to_string(hi) + "]");
      out[i] = static_cast<int>(v[i]);
    }
    return out;
  }

  std::string choice(const std::string& key, const std::string& def, std::initializer_list<const char*> allowed) {
    const std::string v = text(key, def);
    for (const char* a : allowed)
      if (v == a) return v;
    std::string list;
    for (const char* a : allowed) list += (list.empty() ? "" : ", ") + std::string(a);
    fail(key + ": '" + v + "' is not one of " + list);
  }

  // Every attribute must have been consumed.
  void finish() const {
    for (const auto& [k, v] : attrs_)
      if (used_.count(k) == 0) fail("unknown attribute '" + k + "' for '" + keyword_ + "'");
  }

 private:
  double parse_number(const std::string& key, const std::string& s) const {
    double v = 0.0;
    auto [p, ec] = std::from_chars(s.data(), s.data() + s.size(), v);
    if (ec != std::errc() || p != s.data() + s.size() || s.empty() || !std::isfinite(v))
      fail(key + ": '" + s + "' is not a number");
    return v;
  }

  std::string file_;
  int line_;
  std::string keyword_;
  std::map<std::string, std::string> attrs_;
  std::set<std::string> used_;
};

// Upper bound on the highest natural frequency of the scene, omega_max^2 = lambda_max(M^-1 K),
// by Gershgorin's theorem on each node's row: omega^2 <= (sum over the node's row of |K_ij|)
// / m_i. A spring of stiffness k adds k to the diagonal and -k (projected) off it, so 2 k
// per node it touches; an FEM element adds the largest absolute row sum of its 24 x 24
// stiffness matrix; a contact or floor point adds its penalty stiffness (twice the stiffness:
// one pair, both ends). The stiffest node names the object in the messages.
class FrequencyBound {
 public:
  // One node: `row` = sum of |K_ij| over its row, `mass` its mass.
  void node(const std::string& object, double row, double mass) {
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
  // Springs between nodes of `a` (and `b`, or `a` again when null).
  void springs(const std::string& object, const std::vector<Spring>& springs, const Body& a,
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
  void body_rows(const std::string& object, const std::vector<double>& rows, const Body& body) {
    for (std::size_t i = 0; i < rows.size(); ++i)
      if (rows[i] != 0.0) node(object, rows[i], point_mass(body, static_cast<Index>(i)));
  }
  // Mass a force at point i moves: the node's mass, or a rigid body's whole mass.
  static double point_mass(const Body& body, Index i) {
    if (const auto* p = dynamic_cast<const ParticleBody*>(&body)) return p->mass(i);
    return body.total_mass();
  }
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

std::string short_num(double v) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.3g", v);
  return buf;
}

class SceneBuilder {
 public:
  SceneBuilder(std::string file, const SceneOptions& options)
      : file_(std::move(file)), options_(options), jitter_(options.seed) {}

  std::unique_ptr<Scene> build(std::string_view text) {
    std::istringstream in{std::string(text)};
    std::string line;
    int number = 0;
    bool header = false;
    while (std::getline(in, line)) {
      ++number;
      if (auto hash = line.find('#'); hash != std::string::npos) line.resize(hash);
      std::istringstream words(line);
      std::string keyword;
      if (!(words >> keyword)) continue;
      std::map<std::string, std::string> attrs;
      std::vector<std::string> positional;
      std::string word;
      while (words >> word) {
        const auto eq = word.find('=');
        if (eq == std::string::npos) {
          positional.push_back(word);
          continue;
        }
        const std::string key = word.substr(0, eq);
        if (key.empty()) Directive(file_, number, keyword, {}).fail("attribute with an empty name");
        if (!attrs.emplace(key, word.substr(eq + 1)).second)
          Directive(file_, number, keyword, {}).fail("attribute '" + key + "' given twice");
      }
      Directive d(file_, number, keyword, std::move(attrs));
      if (!header) {
        if (keyword != "tgraph-scene" || positional.size() != 1 || positional[0] != "1")
          d.fail("the first line must be 'tgraph-scene 1'");
        header = true;
        continue;
      }
      if (!positional.empty()) d.fail("'" + positional[0] + "' is not a key=value attribute");
      bound_.set_line(number);
      directive(d);
      d.finish();
    }
    if (!header) Directive(file_, number, "", {}).fail("empty scene file (the first line must be 'tgraph-scene 1')");
    if (!scene_) Directive(file_, number, "", {}).fail("no 'scene name=...' line");
    if (scene_->bodies().empty()) Directive(file_, number, "", {}).fail("the scene has no objects");
    if (options_.dt) {
      if (!(*options_.dt > 0.0) || !std::isfinite(*options_.dt)) throw UsageError("--dt must be > 0");
      scene_->solver().dt = *options_.dt;
    }
    if (options_.coupling) scene_->solver().coupling = *options_.coupling;
    check_stability(number);
    return std::move(scene_);
  }

 private:
  void directive(Directive& d) {
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

  void solver(Directive& d) {
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

  void collision(Directive& d) {
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

  Body* body_by_name(Directive& d, const std::string& key) {
    const std::string name = d.text(key);
    Body* b = scene_->find_body(name);
    if (b == nullptr) d.fail(key + ": no object named '" + name + "' (objects must be declared first)");
    return b;
  }

  // Settings the integrator cannot handle: a stiffness that overflows is refused; a time step
  // above the explicit stability limit, or one that leaves CG too few iterations, is a
  // warning (the divergence checks of Scene::step stop a run that does blow up).
  void check_stability(int last_line) {
    const CollisionSettings& c = scene_->collision();
    if (c.enabled) {
      for (const auto& b : scene_->bodies()) {
        if (b->surface.empty()) continue;
        double m = 1e300;
        for (Index i : b->surface) m = std::min(m, FrequencyBound::point_mass(*b, i));
        bound_.node(b->name() + " (contact)", 2.0 * c.stiffness, m);
        if (c.floor) bound_.node(b->name() + " (floor contact)", c.floor_stiffness, m);
      }
    }
    const SolverSettings& s = scene_->solver();
    const std::string where =
        options_.dt ? file_ + " with --dt" : file_ + ":" + std::to_string(dt_line_ > 0 ? dt_line_ : last_line);
    const double w2 = bound_.omega2();
    if (w2 == 0.0) return;
    if (!std::isfinite(w2) || w2 > 1e200)
      throw InputError(file_ + ":" + std::to_string(bound_.object_line()), std::nullopt,
                       "object '" + bound_.object() + "': " +
                           (std::isfinite(bound_.row())
                                ? "stiffness " + short_num(bound_.row()) + " N/m over a node mass of " +
                                      short_num(bound_.mass()) + " kg gives omega_max^2 = " + short_num(w2) + " 1/s^2"
                                : std::string("the stiffness overflows double arithmetic")) +
                           ": expected omega_max^2 = stiffness/mass <= 1e200 1/s^2, which the integrators can "
                           "handle (check young=, stiffness= and density=)");
    const double omega = std::sqrt(w2);
    const double h = s.dt;
    const std::string source = "omega_max <= " + short_num(omega) + " rad/s, from object '" +
                               bound_.object() + "': stiffness " + short_num(bound_.row()) +
                               " N/m on a node of " + short_num(bound_.mass()) + " kg";
    if (s.integrator == Integrator::kExplicitEuler) {
      if (h * omega >= 2.0)
        scene_->add_warning(where + ": dt=" + short_num(h) +
                            " s may be unstable for explicit Euler, stable for dt < 2/omega_max = " +
                            short_num(2.0 / omega) + " s (" + source + ")");
      return;
    }
    // Implicit Euler is stable for any dt, but CG on M - h^2 K needs about
    // sqrt(cond)/2 ln(2/tolerance) iterations, cond <= 1 + h^2 omega_max^2.
    const double cond = 1.0 + h * h * w2;
    const double needed = 0.5 * std::sqrt(cond) * std::log(2.0 / s.tolerance);
    if (!(needed <= s.max_iterations))
      scene_->add_warning(
          where + ": dt=" + short_num(h) + " s makes the implicit system stiff (condition number up to " +
          short_num(cond) + ", " + source + "): CG may need about " + short_num(needed) +
          " iterations, more than max_iterations=" + std::to_string(s.max_iterations));
  }

  // Counts `n` more points (nodes, particles, rigid surface points) against
  // SceneOptions::max_nodes before they are built.
  void add_points(Directive& d, std::uint64_t n) {
    if (n > options_.max_nodes || points_ > options_.max_nodes - n)
      d.fail("expected at most " + std::to_string(options_.max_nodes) +
             " points (nodes, particles and rigid surface points) in the scene, this line brings "
             "it to " + std::to_string(points_ + std::min<std::uint64_t>(n, UINT64_MAX - points_)));
    points_ += n;
  }

  void check_new_name(Directive& d, const std::string& name) {
    if (!names_.insert(name).second) d.fail("an object named '" + name + "' already exists");
  }

  // Attributes every body takes: damping, velocity, collision participation.
  void common(Directive& d, Body& b, double spacing) {
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
  void instance_common(Directive& d, Body& b, double spacing, bool first) {
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

  // split=N (or --split): the object's internal force field as up to N fields over
  // consecutive runs of its elements or springs, each a task of its own (cumulative writes
  // into the object's force vectors), so one big object no longer serialises its force and
  // CG products. Run one after the other, the fields add the same terms into every node in
  // the same order as the whole field (FEM: runs of whole element batches).
  int split_of(Directive& d) {
    const int split = d.integer("split", 1, 1, 1024);
    if (options_.split) {
      if (*options_.split < 1 || *options_.split > 1024) throw UsageError("--split must be in [1, 1024]");
      return *options_.split;
    }
    return split;
  }

  // `units` in order, cut into up to `split` consecutive runs; make(name, run) builds a field.
  template <class Unit, class Make>
  void add_split_fields(const std::string& name, const std::vector<Unit>& units, int split, Make make) {
    const std::size_t per = (units.size() + static_cast<std::size_t>(split) - 1) / static_cast<std::size_t>(split);
    if (split <= 1 || per >= units.size()) {
      scene_->add_force_field(make(name, units.begin(), units.end()));
      return;
    }
    int block = 0;
    for (std::size_t start = 0; start < units.size(); start += per, ++block)
      scene_->add_force_field(make(name + "[" + std::to_string(block) + "]",
                                   units.begin() + static_cast<std::ptrdiff_t>(start),
                                   units.begin() + static_cast<std::ptrdiff_t>(std::min(units.size(), start + per))));
  }

  std::vector<Index> fixed_nodes(Directive& d, const StateVec& x, const std::string& spec) {
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

  void add_gravity(Body& b) {
    if (scene_->gravity().squaredNorm() > 0.0)
      scene_->add_force_field(std::make_unique<GravityForceField>(b.name() + ".gravity", &b, scene_->gravity()));
  }

  void add_fix(Body& b, std::vector<Index> cols) {
    if (!cols.empty()) scene_->add_constraint(std::make_unique<FixedConstraint>(b.name() + ".fixed", &b, std::move(cols)));
  }

  // Instances of an object: array=ax,ay,az spacing=dx,dy,dz, each jittered by jitter=a.
  std::vector<std::pair<std::string, Vec3>> instances(Directive& d, const std::string& name, const Vec3& center) {
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

  void particles(Directive& d) {
    const std::string name = d.text("name");
    check_new_name(d, name);
    const std::string spec = d.text("points");
    std::vector<Vec3> pts;
    std::size_t start = 0;
    while (start <= spec.size()) {
      const std::size_t semi = spec.find(';', start);
      const auto v = d.numbers("points", 3, spec.substr(start, semi == std::string::npos ? std::string::npos : semi - start));
      pts.emplace_back(v[0], v[1], v[2]);
      add_points(d, 1);
      if (semi == std::string::npos) break;
      start = semi + 1;
    }
    StateVec x(3, static_cast<Index>(pts.size()));
    for (std::size_t i = 0; i < pts.size(); ++i) x.col(static_cast<Index>(i)) = pts[i];
    const double mass = d.positive("mass");
    auto body = std::make_unique<ParticleBody>(name, x, std::vector<double>(pts.size(), mass));
    for (Index i = 0; i < x.cols(); ++i) body->surface.push_back(i);
    Body& b = scene_->add_body(std::move(body));
    double spacing = 0.1;
    if (x.cols() > 1 && x.cols() <= kExactSpacingPoints) {
      spacing = 1e300;
      for (Index i = 0; i < x.cols(); ++i)
        for (Index j = i + 1; j < x.cols(); ++j) spacing = std::min(spacing, (x.col(i) - x.col(j)).norm());
    } else if (x.cols() > kExactSpacingPoints) {
      // The closest pair costs n^2/2 distances: estimate from the bounding box instead.
      const Vec3 extent = x.rowwise().maxCoeff() - x.rowwise().minCoeff();
      spacing = extent.norm() / std::cbrt(static_cast<double>(x.cols()));
    }
    common(d, b, spacing);
    add_gravity(b);
    add_fix(b, fixed_nodes(d, x, d.text("fix", "none")));
  }

  void springs(Directive& d) {
    Body* a = body_by_name(d, "a");
    Body* b = d.has("b") ? body_by_name(d, "b") : nullptr;
    if (b == a) b = nullptr;
    const std::string name = d.text("name", b ? "springs[" + a->name() + "|" + b->name() + "]" : a->name() + ".springs");
    check_new_name(d, name);
    const double k = d.positive("stiffness");
    const std::optional<double> rest = d.has("rest") ? std::optional<double>(d.non_negative("rest")) : std::nullopt;
    std::vector<Spring> springs;
    const std::string spec = d.text("pairs");
    std::size_t start = 0;
    Body* other = b ? b : a;
    while (start <= spec.size()) {
      const std::size_t comma = spec.find(',', start);
      const std::string pair = spec.substr(start, comma == std::string::npos ? std::string::npos : comma - start);
      const auto dash = pair.find('-');
      if (dash == std::string::npos) d.fail("pairs: '" + pair + "' is not i-j");
      Index i = 0, j = 0;
      auto r1 = std::from_chars(pair.data(), pair.data() + dash, i);
      auto r2 = std::from_chars(pair.data() + dash + 1, pair.data() + pair.size(), j);
      if (r1.ec != std::errc() || r1.ptr != pair.data() + dash || r2.ec != std::errc() ||
          r2.ptr != pair.data() + pair.size())
        d.fail("pairs: '" + pair + "' is not i-j");
      if (i < 0 || i >= a->num_points() || j < 0 || j >= other->num_points())
        d.fail("pairs: '" + pair + "' names a point out of range");
      springs.push_back({i, j, rest ? *rest : (a->point(i) - other->point(j)).norm(), k});
      if (comma == std::string::npos) break;
      start = comma + 1;
    }
    bound_.springs(name, springs, *a, b);
    scene_->add_force_field(std::make_unique<SpringForceField>(name, a, b, std::move(springs)));
  }

  // fem and springgrid: a hexahedral grid (box or ellipsoid).
  void grid_object(Directive& d) {
    const bool fem = d.keyword() == "fem";
    const std::string name = d.text("name");
    const auto nodes = d.int3("nodes", std::nullopt, 2, 512);
    const std::uint64_t grid_nodes = static_cast<std::uint64_t>(nodes[0]) * nodes[1] * nodes[2];
    if (grid_nodes > (1u << 22)) d.fail("nodes: at most 4194304 nodes per object");
    const auto copies = d.int3("array", std::array<int, 3>{1, 1, 1}, 1, 4096);
    add_points(d, grid_nodes * static_cast<std::uint64_t>(copies[0]) * copies[1] * copies[2]);
    const Vec3 size = d.vec3("size");
    if ((size.array() <= 0.0).any()) d.fail("size: every extent must be > 0");
    const Vec3 center = d.vec3("center", Vec3::Zero());
    const Shape shape = d.choice("shape", "box", {"box", "ellipsoid"}) == "ellipsoid" ? Shape::kEllipsoid : Shape::kBox;
    const double density = d.positive("density", 1000.0);
    FemMaterial mat;
    double k = 0.0;
    if (fem) {
      mat.young = d.positive("young", 1e6);
      mat.poisson = d.number("poisson", 0.3);
      if (!(mat.poisson >= 0.0 && mat.poisson < 0.5)) d.fail("poisson must be in [0, 0.5)");
      mat.incompatible_modes = d.choice("element", "incompatible", {"incompatible", "trilinear"}) == "incompatible";
    } else {
      k = d.positive("stiffness");
    }
    const std::string fix = d.text("fix", "none");
    const int split = split_of(d);
    const HexMesh proto = detail::make_hex_grid(nodes, size, Vec3::Zero(), shape);
    if (proto.elements.empty()) d.fail("the shape contains no element (use more nodes)");
    const std::vector<Spring> springs = fem ? std::vector<Spring>{} : detail::grid_springs(proto, k);
    // Gershgorin rows of one instance (all instances are copies of the prototype).
    std::vector<double> rows(proto.node_volume.size(), 0.0);
    if (fem) {
      Eigen::Matrix<double, 3, 8> corners;
      for (int i = 0; i < 8; ++i) corners.col(i) = proto.nodes.col(proto.elements[0][static_cast<std::size_t>(i)]);
      const double row = HexFemForceField::element_stiffness(corners, mat).cwiseAbs().rowwise().sum().maxCoeff();
      for (const auto& e : proto.elements)
        for (Index n : e) rows[static_cast<std::size_t>(n)] += row;
    } else {
      for (const Spring& sp : springs) {
        rows[static_cast<std::size_t>(sp.i)] += 2.0 * sp.stiffness;
        rows[static_cast<std::size_t>(sp.j)] += 2.0 * sp.stiffness;
      }
    }
    bool first = true;
    for (const auto& [inst, c] : instances(d, name, center)) {
      check_new_name(d, inst);
      StateVec x = proto.nodes;
      x.colwise() += c;
      std::vector<double> masses(proto.node_volume.size());
      for (std::size_t i = 0; i < masses.size(); ++i) masses[i] = density * proto.node_volume[i];
      auto body = std::make_unique<ParticleBody>(inst, x, std::move(masses));
      ParticleBody* pb = body.get();
      if (first) bound_.body_rows(inst, rows, *pb);
      pb->surface = proto.surface;
      pb->triangles = proto.triangles;
      scene_->add_body(std::move(body));
      instance_common(d, *pb, proto.spacing.minCoeff(), first);
      first = false;
      add_gravity(*pb);
      if (fem && split > 1) {
        const HexFemForceField whole(inst + ".fem", pb, proto.elements, mat);
        add_split_fields(inst + ".fem", whole.element_batches(), split, [&](const std::string& n, auto first, auto last) {
          std::vector<std::array<Index, 8>> elements;
          for (auto it = first; it != last; ++it) elements.insert(elements.end(), it->begin(), it->end());
          return std::make_unique<HexFemForceField>(n, pb, std::move(elements), mat, &whole);
        });
      } else if (fem) {
        scene_->add_force_field(std::make_unique<HexFemForceField>(inst + ".fem", pb, proto.elements, mat));
      } else {
        add_split_fields(inst + ".springs", springs, split, [&](const std::string& n, auto first, auto last) {
          return std::make_unique<SpringForceField>(n, pb, nullptr, std::vector<Spring>(first, last));
        });
      }
      add_fix(*pb, fixed_nodes(d, x, fix));
    }
  }

  void rigid(Directive& d) {
    const std::string name = d.text("name");
    const std::string shape = d.choice("shape", "box", {"box", "sphere"});
    const int res = d.integer("res", 8, 2, 256);
    const double density = d.positive("density", 1000.0);
    const Vec3 center = d.vec3("center", Vec3::Zero());
    detail::RigidSurface surf;
    double mass = 0.0;
    Mat3 inertia = Mat3::Zero();
    if (shape == "box") {
      const Vec3 size = d.vec3("size");
      if ((size.array() <= 0.0).any()) d.fail("size: every extent must be > 0");
      surf = detail::box_surface(size, res);
      mass = density * size.prod();
      inertia.diagonal() << mass / 12.0 * (size.y() * size.y() + size.z() * size.z()),
          mass / 12.0 * (size.x() * size.x() + size.z() * size.z()),
          mass / 12.0 * (size.x() * size.x() + size.y() * size.y());
    } else {
      const double r = d.positive("size");
      surf = detail::sphere_surface(r, res);
      mass = density * 4.0 / 3.0 * M_PI * r * r * r;
      inertia = Mat3::Identity() * (0.4 * mass * r * r);
    }
    {
      const auto copies = d.int3("array", std::array<int, 3>{1, 1, 1}, 1, 4096);
      add_points(d, static_cast<std::uint64_t>(surf.points.cols()) * copies[0] * copies[1] * copies[2]);
    }
    Eigen::Quaterniond q = Eigen::Quaterniond::Identity();
    if (d.has("rotation")) {
      const auto v = d.numbers("rotation", 4, d.text("rotation"));
      const Vec3 axis(v[0], v[1], v[2]);
      if (axis.norm() == 0.0) d.fail("rotation: the axis must not be zero");
      q = Eigen::AngleAxisd(v[3] * M_PI / 180.0, axis.normalized());
    }
    const double spin = d.non_negative("spin", 0.0);
    const bool fixed = d.choice("fix", "none", {"none", "all"}) == "all";
    bool first = true;
    for (const auto& [inst, c] : instances(d, name, center)) {
      check_new_name(d, inst);
      Eigen::Quaterniond qi = q;
      if (spin > 0.0) {
        Vec3 axis = jitter_.vec();
        if (axis.norm() < 1e-6) axis = Vec3::UnitY();
        qi = Eigen::AngleAxisd(spin * jitter_.uniform() * M_PI / 180.0, axis.normalized()) * q;
      }
      auto body = std::make_unique<RigidBody>(inst, mass, inertia, c, qi, surf.points);
      RigidBody* rb = body.get();
      for (Index i = 0; i < surf.points.cols(); ++i) rb->surface.push_back(i);
      rb->triangles = surf.triangles;
      scene_->add_body(std::move(body));
      instance_common(d, *rb, surf.spacing, first);
      first = false;
      if (fixed)
        add_fix(*rb, {0, 1});
      else
        add_gravity(*rb);
    }
  }

  // A serpentine chain of particles (the torso's intestine): stretch and bending springs;
  // `array=` makes copies (name0, name1, ...) like the grid objects.
  void chain(Directive& d) {
    const std::string name = d.text("name");
    const int n = d.integer("nodes", std::nullopt, 3, 1000000);
    {
      const auto copies = d.int3("array", std::array<int, 3>{1, 1, 1}, 1, 4096);
      add_points(d, static_cast<std::uint64_t>(n) * copies[0] * copies[1] * copies[2]);
    }
    const int rows = d.integer("rows", 1, 1, n);
    const double seg = d.positive("segment");
    const Vec3 center = d.vec3("center", Vec3::Zero());
    const double k = d.positive("stiffness");
    const double kb = d.non_negative("bend", 0.0);
    const double mass = d.positive("mass");
    const int per_row = (n + rows - 1) / rows;
    StateVec proto(3, n);
    const double width = seg * (per_row - 1);
    const double row_gap = d.positive("row_gap", 2.0 * seg);
    for (int i = 0; i < n; ++i) {
      const int row = i / per_row;
      int col = i % per_row;
      if (row % 2 == 1) col = per_row - 1 - col;
      proto.col(i) = Vec3(col * seg - 0.5 * width, 0.0, row * row_gap - 0.5 * row_gap * (rows - 1));
    }
    std::vector<Spring> springs;
    for (Index i = 0; i + 1 < n; ++i) springs.push_back({i, i + 1, (proto.col(i + 1) - proto.col(i)).norm(), k});
    if (kb > 0.0)
      for (Index i = 0; i + 2 < n; ++i) springs.push_back({i, i + 2, (proto.col(i + 2) - proto.col(i)).norm(), kb});
    const std::string fix = d.text("fix", "none");
    const int split = split_of(d);
    bool first = true;
    for (const auto& [inst, c] : instances(d, name, center)) {
      check_new_name(d, inst);
      StateVec x = proto;
      x.colwise() += c;
      auto body = std::make_unique<ParticleBody>(inst, x, std::vector<double>(static_cast<std::size_t>(n), mass / n));
      for (Index i = 0; i < n; ++i) body->surface.push_back(i);
      Body& b = scene_->add_body(std::move(body));
      if (first) bound_.springs(inst, springs, b, nullptr);
      instance_common(d, b, seg, first);
      first = false;
      add_gravity(b);
      add_split_fields(inst + ".springs", springs, split, [&](const std::string& fn, auto first, auto last) {
        return std::make_unique<SpringForceField>(fn, &b, nullptr, std::vector<Spring>(first, last));
      });
      add_fix(b, fixed_nodes(d, x, fix));
    }
  }

  // An N x N mass-spring sheet cut into split x split sub-objects joined by interaction
  // springs (the paper's domain decomposition, section 4.3).
  void cloth(Directive& d) {
    const std::string name = d.text("name");
    const int n = d.integer("nodes", std::nullopt, 2, 2048);
    int split = d.integer("split", 4, 1, 1024);
    if (options_.subobjects) {
      const int s = static_cast<int>(std::lround(std::sqrt(static_cast<double>(*options_.subobjects))));
      if (*options_.subobjects < 1 || s * s != *options_.subobjects)
        throw UsageError("--subobjects must be a perfect square (1, 4, 9, 16, ...)");
      split = s;
    }
    if (split > n) d.fail("split must not exceed nodes");
    add_points(d, static_cast<std::uint64_t>(n) * static_cast<std::uint64_t>(n));
    const double size = d.positive("size");
    const Vec3 center = d.vec3("center", Vec3::Zero());
    const double k = d.positive("stiffness");
    const double ks = d.non_negative("shear", 0.5 * k);
    const double kb = d.non_negative("bend", 0.0);
    const double total_mass = d.positive("mass");
    const double damping = d.non_negative("damping", 0.0);
    const std::string fix = d.choice("fix", "corners", {"none", "corners", "edge"});
    const double h = size / (n - 1);
    auto block_of = [&](int i) { return static_cast<int>(static_cast<long long>(i) * split / n); };
    // Local numbering inside each block.
    std::vector<int> block(static_cast<std::size_t>(n) * static_cast<std::size_t>(n));
    std::vector<Index> local(block.size());
    std::vector<std::vector<Vec3>> pos(static_cast<std::size_t>(split * split));
    for (int j = 0; j < n; ++j)
      for (int i = 0; i < n; ++i) {
        const int bidx = block_of(i) + split * block_of(j);
        const std::size_t node = static_cast<std::size_t>(i) + static_cast<std::size_t>(n) * static_cast<std::size_t>(j);
        block[node] = bidx;
        auto& p = pos[static_cast<std::size_t>(bidx)];
        local[node] = static_cast<Index>(p.size());
        p.push_back(center + Vec3(i * h - 0.5 * size, 0.0, j * h - 0.5 * size));
      }
    std::vector<ParticleBody*> bodies;
    const double node_mass = total_mass / (static_cast<double>(n) * n);
    for (int bj = 0; bj < split; ++bj)
      for (int bi = 0; bi < split; ++bi) {
        const std::string bname = split == 1 ? name : name + "_" + std::to_string(bi) + "_" + std::to_string(bj);
        check_new_name(d, bname);
        const auto& p = pos[static_cast<std::size_t>(bi + split * bj)];
        StateVec x(3, static_cast<Index>(p.size()));
        for (std::size_t v = 0; v < p.size(); ++v) x.col(static_cast<Index>(v)) = p[v];
        auto body = std::make_unique<ParticleBody>(bname, x, std::vector<double>(p.size(), node_mass));
        body->mass_damping = damping;
        bodies.push_back(body.get());
        scene_->add_body(std::move(body));
      }
    for (ParticleBody* b : bodies) add_gravity(*b);
    // Springs, sorted into internal fields and interaction fields by the blocks they join.
    std::vector<std::vector<Spring>> internal(bodies.size());
    std::map<std::pair<int, int>, std::vector<Spring>> ties;
    std::vector<double> rows(block.size(), 0.0);
    auto add = [&](int i0, int j0, int i1, int j1, double stiffness) {
      if (stiffness <= 0.0 || i1 < 0 || i1 >= n || j1 >= n) return;
      const std::size_t a = static_cast<std::size_t>(i0) + static_cast<std::size_t>(n) * static_cast<std::size_t>(j0);
      const std::size_t b = static_cast<std::size_t>(i1) + static_cast<std::size_t>(n) * static_cast<std::size_t>(j1);
      rows[a] += 2.0 * stiffness;
      rows[b] += 2.0 * stiffness;
      const double rest = h * std::hypot(i1 - i0, j1 - j0);
      if (block[a] == block[b]) {
        internal[static_cast<std::size_t>(block[a])].push_back({local[a], local[b], rest, stiffness});
      } else if (block[a] < block[b]) {
        ties[{block[a], block[b]}].push_back({local[a], local[b], rest, stiffness});
      } else {
        ties[{block[b], block[a]}].push_back({local[b], local[a], rest, stiffness});
      }
    };
    for (int j = 0; j < n; ++j)
      for (int i = 0; i < n; ++i) {
        add(i, j, i + 1, j, k);
        add(i, j, i, j + 1, k);
        add(i, j, i + 1, j + 1, ks);
        add(i + 1, j, i, j + 1, ks);
        add(i, j, i + 2, j, kb);
        add(i, j, i, j + 2, kb);
      }
    for (const double row : rows) bound_.node(name, row, node_mass);
    for (std::size_t b = 0; b < bodies.size(); ++b)
      scene_->add_force_field(
          std::make_unique<SpringForceField>(bodies[b]->name() + ".springs", bodies[b], nullptr, std::move(internal[b])));
    for (auto& [key, springs] : ties) {
      ParticleBody* a = bodies[static_cast<std::size_t>(key.first)];
      ParticleBody* b = bodies[static_cast<std::size_t>(key.second)];
      scene_->add_force_field(std::make_unique<SpringForceField>("ties[" + a->name() + "|" + b->name() + "]", a, b,
                                                                 std::move(springs)));
    }
    // Fixed nodes: the two corners of the first row, or the whole first row.
    std::map<int, std::vector<Index>> fixed;
    if (fix == "corners") {
      for (int i : {0, n - 1}) fixed[block[static_cast<std::size_t>(i)]].push_back(local[static_cast<std::size_t>(i)]);
    } else if (fix == "edge") {
      for (int i = 0; i < n; ++i) fixed[block[static_cast<std::size_t>(i)]].push_back(local[static_cast<std::size_t>(i)]);
    }
    for (auto& [bidx, cols] : fixed) add_fix(*bodies[static_cast<std::size_t>(bidx)], std::move(cols));
  }

  std::string file_;
  SceneOptions options_;
  Jitter jitter_;
  std::unique_ptr<Scene> scene_;
  std::set<std::string> names_;
  std::uint64_t points_ = 0;  // counted by add_points()
  FrequencyBound bound_;      // of the objects built so far
  int dt_line_ = 0;           // line of the solver directive, 0 if none
  // Attributes shared by the instances of an array (parsed on the first one).
  double damping_ = 0.0;
  Vec3 velocity_ = Vec3::Zero();
  double radius_ = 0.0;
  int layer_ = 0;
  bool collide_ = true;
};

}  // namespace

std::vector<std::string> builtin_scene_names() {
  std::vector<std::string> out;
  for (std::size_t i = 0; i < detail::kBuiltinSceneCount; ++i) out.emplace_back(detail::kBuiltinScenes[i].name);
  return out;
}

std::optional<std::string_view> builtin_scene_text(std::string_view name) {
  for (std::size_t i = 0; i < detail::kBuiltinSceneCount; ++i)
    if (name == detail::kBuiltinScenes[i].name) return std::string_view(detail::kBuiltinScenes[i].text);
  return std::nullopt;
}

std::unique_ptr<Scene> parse_scene(std::string_view text, std::string_view file, const SceneOptions& options) {
  return SceneBuilder(std::string(file), options).build(text);
}

std::unique_ptr<Scene> make_scene(std::string_view name_or_path, const SceneOptions& options) {
  if (auto text = builtin_scene_text(name_or_path)) return parse_scene(*text, std::string(name_or_path), options);
  const std::string path(name_or_path);
  std::error_code ec;
  if (!std::filesystem::is_regular_file(path, ec)) {
    std::string names;
    for (const auto& n : builtin_scene_names()) names += (names.empty() ? "" : ", ") + n;
    throw InputError(path, std::nullopt, "no such scene file, and not a built-in scene (" + names + ")");
  }
  std::ifstream in(path, std::ios::binary);
  if (!in) throw InputError(path, std::nullopt, "cannot open the scene file");
  std::ostringstream ss;
  ss << in.rdbuf();
  const std::string text = ss.str();
  if (text.size() > (64u << 20)) throw InputError(path, std::nullopt, "scene file larger than 64 MiB");
  return parse_scene(text, path, options);
}

}  // namespace tgraph::samples
