// SPDX-License-Identifier: MIT
// A scene: bodies, force fields, constraints, collision and solver settings, and the
// instrumented time step (the coordination code that issues tasks to a capture::Recorder).
#pragma once

#include <cstdint>
#include <map>
#include <memory>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "tgraph/capture/recorder.hpp"
#include "tgraph/samples/body.hpp"
#include "tgraph/samples/constraint.hpp"
#include "tgraph/samples/force_field.hpp"
#include "tgraph/samples/solver.hpp"

namespace tgraph::samples {

/// Collision detection settings. Detection is a bounding-box broad phase between bodies, then
/// a proximity narrow phase between surface points (spheres of radius Body::contact_radius) of
/// the two bodies, and between surface points and the floor plane. The proxies (surface points
/// and bounds) and the narrow phases are tasks at the end of each step's graph, whose results
/// the next step's host work merges in a fixed order (the same contacts as a sequential pass).
struct CollisionSettings {
  bool enabled = false;
  /// false: the whole detection runs sequentially on the host at the start of each step (the
  /// reference the in-graph detection is tested against; same contacts, same physics).
  bool in_graph = true;
  double alarm_distance = 0.01;  ///< a pair is kept while d < ra + rb + alarm_distance
  double stiffness = 1e4;        ///< penalty stiffness of one contact pair (N/m)
  double damping = 0.0;          ///< normal damping of one contact pair (N s/m)
  double friction = 0.0;         ///< tangential (viscous) damping of one contact pair (N s/m)
  bool floor = false;            ///< a static floor plane y = floor_height
  double floor_height = 0.0;
  double floor_stiffness = 1e4;  ///< penalty stiffness of one point on the floor (N/m)
  double floor_friction = 0.0;   ///< tangential damping of a point on the floor (N s/m)
};

/// Overrides applied when a scene is built.
struct SceneOptions {
  std::optional<double> dt;          ///< time step
  std::uint64_t seed = 1;            ///< random placement jitter (scenes that use it)
  std::optional<int> subobjects;     ///< cloth scenes: number of sub-objects (a square)
  std::optional<Coupling> coupling;  ///< solver sharing
  /// Deformable objects (fem, springgrid, chain): split each internal force field into this
  /// many tasks over element or spring ranges (overrides the scene file's split=).
  std::optional<int> split;
  /// Ceiling on the points of a scene file (nodes, particles, rigid surface points), checked
  /// before each object is built.
  std::uint64_t max_nodes = std::uint64_t{1} << 24;
};

/// What the last step did (known after the step in capture and off modes).
struct StepStats {
  std::uint32_t groups = 0;          ///< collision groups (solver instances)
  std::uint32_t interactions = 0;    ///< interacting body pairs (permanent + contacts)
  std::uint32_t contact_fields = 0;  ///< penalty contact interactions alive
  std::uint64_t contact_pairs = 0;   ///< point pairs in those interactions
  std::uint32_t narrow_tasks = 0;    ///< narrow-phase tasks recorded (body pairs and floor)
  std::uint32_t host_narrow = 0;     ///< narrow phases the host ran (no task of the last step had)
  std::uint32_t cg_iterations = 0;   ///< max CG iterations over the groups (implicit)
  double cg_residual = 0.0;          ///< max relative residual |r|/|b| reached
};

/// A simulated scene.
///
///   auto scene = make_scene("bars64");
///   capture::Recorder rec(capture::Mode::kCapture);
///   for (int i = 0; i < 20; ++i) {
///     scene->step(rec);             // collision detection, then the recorded time step
///     StepGraph g = rec.end_step();
///   }
///
/// step() calls rec.begin_step() and leaves the step open so that the caller ends it with
/// end_step() or end_step_program(). In deferred mode the caller must run the returned
/// program before the next step() (task bodies reference the scene's state). A scene keeps
/// the ids it declared in one recorder; stepping it through another recorder re-declares.
class Scene {
 public:
  explicit Scene(std::string name);
  ~Scene();
  Scene(const Scene&) = delete;
  Scene& operator=(const Scene&) = delete;

  /// Adds a body (owned by the scene).
  Body& add_body(std::unique_ptr<Body> body);
  /// Adds a force field (internal or permanent interaction).
  ForceField& add_force_field(std::unique_ptr<ForceField> field);
  /// Adds a fixed-point constraint.
  FixedConstraint& add_constraint(std::unique_ptr<FixedConstraint> constraint);
  /// Solver settings.
  SolverSettings& solver() { return solver_; }
  const SolverSettings& solver() const { return solver_; }
  /// Collision settings.
  CollisionSettings& collision() { return collision_; }
  const CollisionSettings& collision() const { return collision_; }
  /// Gravity (added as one GravityForceField per body by the scene builders).
  const Vec3& gravity() const { return gravity_; }
  void set_gravity(const Vec3& g) { gravity_ = g; }
  /// Steps a capture runs when none is asked for.
  int default_steps() const { return default_steps_; }
  void set_default_steps(int steps) { default_steps_ = steps; }

  /// Runs one time step: the host part of collision detection (merging the contact sets the
  /// last step's detection tasks found), then rec.begin_step(), the contact set, every
  /// solver's tasks, and the detection tasks for the next step. The step is left open.
  void step(capture::Recorder& rec);
  /// For live runs that keep the program of the last step recorded into `rec` (deferred
  /// mode): runs collision detection; when the step's interactions and collision groups
  /// are those of that step, advances without recording and returns false (its bodies
  /// point at the same state, so the caller runs the kept program again, as the paper
  /// re-executes an unchanged graph); otherwise records like step() and returns true.
  bool step_if_changed(capture::Recorder& rec);

  /// Scene name.
  const std::string& name() const { return name_; }
  /// Simulated time.
  double time() const { return time_; }
  /// Steps run.
  std::uint64_t steps_run() const { return steps_run_; }
  /// Bodies in creation order.
  const std::vector<std::unique_ptr<Body>>& bodies() const { return bodies_; }
  /// Body by name, or nullptr.
  Body* find_body(std::string_view name) const;
  /// Force fields (internal and permanent interactions), in creation order.
  const std::vector<std::unique_ptr<ForceField>>& force_fields() const { return fields_; }
  /// Constraints.
  const std::vector<std::unique_ptr<FixedConstraint>>& constraints() const { return constraints_; }
  /// Penalty contact interactions alive now.
  std::vector<const ContactForceField*> contact_fields() const;
  /// Floor contact fields (one per body with a surface when the scene has a floor).
  std::vector<const FloorContactForceField*> floor_fields() const;
  /// Kinetic energy of all bodies.
  double kinetic_energy() const;
  /// Potential energy of all force fields, contacts included (at the current positions).
  double potential_energy() const;
  /// Statistics of the last step (CG figures once its tasks have run).
  StepStats last_stats() const;
  /// Total surface triangles of the bodies.
  std::uint64_t surface_triangles() const;
  /// Settings the integrator may not handle well, found when the scene was built (a time
  /// step above the explicit stability limit, a CG that cannot converge in max_iterations);
  /// see samples/scenes/README.md. The command line prints them.
  const std::vector<std::string>& warnings() const { return warnings_; }
  /// Adds a warning.
  void add_warning(std::string warning) { warnings_.push_back(std::move(warning)); }

  /// Private state (defined in the library).
  struct Impl;

 private:
  void finalize();
  bool advance(capture::Recorder& rec, bool allow_reuse);
  std::string name_;
  std::vector<std::unique_ptr<Body>> bodies_;
  std::vector<std::unique_ptr<ForceField>> fields_;
  std::vector<std::unique_ptr<FixedConstraint>> constraints_;
  SolverSettings solver_;
  CollisionSettings collision_;
  Vec3 gravity_ = Vec3(0.0, -9.81, 0.0);
  int default_steps_ = 100;
  double time_ = 0.0;
  std::uint64_t steps_run_ = 0;
  StepStats stats_;
  std::vector<std::string> warnings_;
  std::unique_ptr<Impl> impl_;
};

/// Names of the built-in scenes (fig2, bars64, falling, cloth128, cloth256, cloth512, torso).
std::vector<std::string> builtin_scene_names();
/// Text of a built-in scene file (the same as samples/scenes/<name>.scene), or nullopt.
std::optional<std::string_view> builtin_scene_text(std::string_view name);
/// Builds a built-in scene by name, or reads a scene file (a path; format in
/// samples/scenes/README.md). Throws tgraph::InputError ("file:line: reason") on a bad file
/// or a name that is neither built in nor a file; tgraph::UsageError for bad options.
std::unique_ptr<Scene> make_scene(std::string_view name_or_path, const SceneOptions& options = {});
/// Builds a scene from scene-file text; `file` names it in error messages.
std::unique_ptr<Scene> parse_scene(std::string_view text, std::string_view file,
                                   const SceneOptions& options = {});

}  // namespace tgraph::samples
