// SPDX-License-Identifier: MIT
// Private state of a Scene: recorder bindings, collision pipeline, solver instances.
#pragma once

#include <array>
#include <functional>
#include <limits>
#include <map>
#include <memory>
#include <string>
#include <unordered_map>
#include <utility>
#include <vector>

#include "tgraph/samples/scene.hpp"

namespace tgraph::samples::detail {

inline constexpr DatumId kNoDatum = std::numeric_limits<DatumId>::max();

/// A body's collision proxy: the world positions of its surface points and their bounds.
/// Its updateProxy task writes it at the end of a step (from the positions the step left);
/// the narrow-phase tasks of the same step read it.
struct CollisionProxy {
  std::vector<Vec3> points;         // by surface point, storage fixed when the scene finalizes
  Eigen::AlignedBox3d box;          // bounds of `points` (empty without a surface)
  double motion = 0.0;              // largest point displacement since the previous update
  bool filled = false;              // updated at least once (`motion` is meaningful)
  std::uint64_t epoch = 0;          // CollisionState::epoch it was updated for (0: never)
};

/// What one narrow-phase task found: a body pair's contact pairs, or a body's points near the
/// floor. Addresses are stable for the scene's life (kept programs point at them).
struct ContactSlot {
  std::vector<ContactPair> pairs;   // body pair: in the sequential detection's order
  std::vector<Index> floor_points;  // floor: surface points near the plane, in surface order
  std::uint64_t epoch = 0;          // CollisionState::epoch it was computed for (0: never)
};

/// Collision detection split between the step graph and the host. The tasks a step records
/// (proxies, then one narrow phase per planned body pair and per planned floor contact) run at
/// its end and find the contacts of the next step; the next step's host merge takes their
/// results, in a fixed order, and runs on the host only the narrow phases no task covered.
struct CollisionState {
  /// Epoch the tasks of the last recorded or reused program stamp their results with (0: the
  /// last program had none). The host sets it before the program runs; tasks read it.
  std::uint64_t epoch = 0;
  std::uint64_t next_epoch = 1;
  std::vector<CollisionProxy> proxies;                                   // by body
  std::map<std::pair<int, int>, std::unique_ptr<ContactSlot>> pair_slots;  // by body pair
  std::vector<std::unique_ptr<ContactSlot>> floor_slots;                 // by Impl::floors
  std::vector<char> may_collide;       // by body: has a surface, not fixed everywhere
  std::vector<std::pair<int, int>> planned_pairs;  // narrow-phase tasks of this step, in order
  std::vector<int> planned_floors;                 // floor-phase tasks (Impl::floors indices)
  std::uint32_t host_narrow = 0;  // narrow phases the last merge ran on the host
};

/// Scalars and ids of one CG solver instance (one per collision group, or one shared).
/// Task bodies reference these fields, so an instance lives as long as the scene.
struct GroupSolver {
  std::string name;
  int first_body = 0;  // body whose group this solver serves
  // CG scalars (each a shared datum of the graph). The two that CW writers add into while
  // other threads read the rest have cache lines of their own (no false sharing).
  double rho = 0.0;                   // r.r of the previous iteration
  alignas(64) double rho_new = 0.0;   // r.r of this iteration (partial sums CW)
  alignas(64) double den = 0.0;       // p.q (partial sums CW)
  alignas(64) double beta = 0.0;      // rho_new / rho
  double b2 = 0.0;       // |b|^2 (tolerance reference)
  bool converged = false;  // the loop's condition datum
  std::uint32_t iterations = 0;
  double residual = 0.0;  // |r| / |b| reached
  std::uint32_t stalled_steps = 0;  // consecutive steps ended at max_iterations unconverged
  // Recorder ids (valid for Binding::generation == generation).
  std::uint64_t generation = 0;
  ObjectId object = kNoObject;
  DatumId d_rho = kNoDatum, d_rho_new = kNoDatum, d_den = kNoDatum, d_beta = kNoDatum,
          d_b2 = kNoDatum, d_cond = kNoDatum;
};

/// Ids declared in one recorder.
struct Binding {
  const capture::Recorder* rec = nullptr;
  std::uint64_t generation = 0;
  KindId reset_force = 0, add_force = 0, add_dforce = 0, project = 0, update_velocity = 0,
         update_position = 0, compute_rhs = 0, dot = 0, cg_init = 0, cg_start = 0,
         cg_direction = 0, add_mdx = 0, cg_update = 0, cg_scalars = 0, update_proxy = 0,
         collide_pair = 0, collide_floor = 0;
  std::vector<ObjectId> body_object;                        // per body index
  std::vector<std::array<DatumId, kVecCount>> body_vec;     // per body index
  std::unordered_map<std::string, ObjectId> field_object;   // interaction fields
  std::unordered_map<std::string, DatumId> field_state;     // fields with cached state
  std::unordered_map<ObjectId, int> object_body;            // object -> a body (for groups)
  std::vector<DatumId> body_proxy;                          // per body index (kNoDatum: none yet)
  std::map<std::pair<int, int>, DatumId> pair_contacts;     // per body pair: its contact set
  std::vector<DatumId> floor_contacts;                      // per Impl::floors index
};

/// A force field with its recorder ids, resolved once per step.
struct FieldRef {
  ForceField* ff = nullptr;
  ObjectId object = kNoObject;
  DatumId state = kNoDatum;
  int body_a = -1;
  int body_b = -1;  // -1: not an interaction
};

/// One solver instance's share of the scene this step.
struct Group {
  std::vector<int> bodies;
  std::vector<ForceField*> fields;
  std::vector<FixedConstraint*> constraints;
  std::vector<FieldRef> refs;  // fields with their ids (filled by the stepper)
  GroupSolver* solver = nullptr;
};

}  // namespace tgraph::samples::detail

namespace tgraph::samples::detail {
/// Reference values of the divergence checks (samples/src/divergence.cpp).
struct DivergenceState {
  bool have_baseline = false;
  double kinetic0 = 0.0;    // kinetic energy at the first step
  double internal0 = 0.0;   // potential energy of the fields other than gravity, then
  double gravity0 = 0.0;    // gravity potential energy, then
  std::uint64_t checked = 0;  // steps_run() when last checked
};
}  // namespace tgraph::samples::detail

namespace tgraph::samples {

struct Scene::Impl {
  bool finalized = false;
  detail::DivergenceState divergence;
  std::unordered_map<const Body*, int> body_index;
  std::vector<std::vector<ForceField*>> body_fields;  // internal fields per body, floor included
  std::vector<std::vector<FixedConstraint*>> body_constraints;
  std::vector<char> immobile;  // every column of the body is fixed
  std::vector<ForceField*> interactions;  // permanent interaction fields
  std::vector<std::unique_ptr<FloorContactForceField>> floors;
  std::map<std::pair<int, int>, std::unique_ptr<ContactForceField>> contacts;
  detail::CollisionState collide;
  std::map<std::string, std::unique_ptr<detail::GroupSolver>> solvers;
  std::vector<detail::Group> groups;
  std::vector<int> body_group;
  detail::Binding bind;
  std::uint64_t next_generation = 1;
  // What the step last recorded into `bind.rec` interacted and how bodies were grouped
  // (Scene::step_if_changed reuses that recording while it repeats).
  std::vector<const void*> recorded_shape;
};

namespace detail {
/// Host part of collision detection at the start of a step: takes the contact sets the last
/// step's tasks found (computing on the host what no task covered), then updates the floor
/// points and creates/removes contact fields in the sequential detection's order.
void detect_collisions(Scene& scene, Scene::Impl& impl);
/// Chooses the narrow-phase tasks this step records (CollisionState::planned_*): body pairs and
/// floor contacts whose bounds, grown by twice the motion of the last step, are within reach.
void plan_detection(Scene& scene, Scene::Impl& impl);
/// Declares the interaction objects of the planned body pairs (before the step's contact set
/// and groups are set, so that every object has a group).
void declare_detection(Scene& scene, Scene::Impl& impl, capture::Recorder& rec);
/// Records the detection tasks at the end of the step: updateProxy per body (reads its x),
/// collidePair per planned pair and collideFloor per planned floor contact (read proxies,
/// write the contact set). `x_of(body)` is the datum of a body's positions.
void record_detection(Scene& scene, Scene::Impl& impl, capture::Recorder& rec,
                      const std::function<DatumId(int)>& x_of);
/// Collision groups: the connected components of the interactions (permanent and contact
/// fields; one group under Coupling::kShared) into `impl.groups` and `impl.body_group`, each
/// with its bodies' fields and constraints, its interactions and its solver (samples/src/scene.cpp).
/// Returns the interactions, permanent first.
std::vector<ForceField*> form_groups(const Scene& scene, Scene::Impl& impl);
/// Divergence checks of the state the last executed step left (samples/src/divergence.cpp):
/// throws DivergenceError; the first call records the reference energies.
void check_divergence(const Scene& scene, Scene::Impl& impl);
}  // namespace detail

}  // namespace tgraph::samples
