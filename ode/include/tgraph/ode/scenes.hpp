// SPDX-License-Identifier: MIT
// ODE scenes made with ODE's public API: ode-piles (many islands), ode-heap (one big island),
// ode-chains (joint-heavy). Each step: dSpaceCollide (sweep-and-prune space, ground plane,
// contacts dContactApprox1 | dContactSoftERP, mu 0.5, soft_erp 0.5, up to 4 per pair), the
// world step (dt 0.005), the contact group emptied.
#pragma once

#include <ode/ode.h>

#include <cstdint>
#include <memory>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

#include "tgraph/ode/method.hpp"

namespace tgraph::ode {

class Attachment;

/// True for ode-piles, ode-heap and ode-chains.
bool is_scene(std::string_view name);
/// The scenes' names.
std::vector<std::string> scene_names();
/// The steps `tgraph run` and `tgraph capture` take by default on a scene (400 for ode-heap,
/// 200 for the others).
std::uint32_t default_steps(std::string_view scene);

/// How long one step of a scene took.
struct StepTime {
  std::int64_t collide_ns = 0;  ///< dSpaceCollide (and the contact joints it makes)
  std::int64_t world_ns = 0;    ///< the world step
};

/// One ODE world with its space, bodies and joints; ODE must be initialised (dInitODE2).
///
///   auto scene = tgraph::ode::Scene::make("ode-piles");
///   tgraph::ode::Attachment attach(scene->world(), options);
///   for (int i = 0; i < 200; ++i) scene->step(&attach);
class Scene {
 public:
  /// InputError naming the scene for an unknown name. Seeds ODE's random numbers (its
  /// constraint reordering draws them) with `seed`, so that runs compare.
  static std::unique_ptr<Scene> make(std::string_view name, Stepper stepper = Stepper::kQuickStep,
                                     unsigned long seed = 0);
  ~Scene();
  Scene(const Scene&) = delete;
  Scene& operator=(const Scene&) = delete;

  const std::string& name() const { return name_; }
  dWorldID world() const { return world_; }
  dSpaceID space() const { return space_; }
  Stepper stepper() const { return stepper_; }
  static constexpr dReal kDt = 0.005;
  /// The steps `tgraph run` and `tgraph capture` take by default.
  std::uint32_t default_steps() const;
  /// One step: collision (timed through `attach` when given), the world step (through it
  /// when given, else ODE directly), the contacts emptied.
  StepTime step(Attachment* attach);

  std::size_t bodies() const { return bodies_.size(); }
  /// Moves every body by `dx` along x (the scenes are invariant under it): a perturbation of
  /// the size of rounding, whose growth is what rounding alone can do to a run.
  void nudge(double dx);
  /// From now on each self-threaded step's (step(nullptr)) contact joints are made in an
  /// order shuffled with `seed` (0: the collision's own order, the default): the same
  /// contacts, which ODE's constraint solvers then take in another order. A K-thread run reorders
  /// them so (K island jobs mark their bodies' geoms moved in the order they step them, and the
  /// collision space keeps moved geoms in that order); `run --check` measures what this does to ODE
  /// self-threaded.
  void shuffle_contacts(unsigned long seed);
  /// Every body's position, quaternion, linear and angular velocity (13 numbers a body).
  std::vector<double> state() const;
  /// The scene's length scale (m): its box edge or link length.
  double length_scale() const { return length_; }
  /// How deep the lowest body vertex is below the floor (m; <= 0 when none is below).
  double depth_below_floor() const;
  /// The fastest body's linear speed (m/s) and the fastest angular speed (rad/s).
  double max_speed() const;
  double max_angular_speed() const;
  /// The bodies' root-mean-square linear speed (m/s): their kinetic energy as one speed.
  double rms_speed() const;
  /// ode-chains: the largest distance between a hinge's two anchors over the link length
  /// (ODE's joint error; 0 for the other scenes).
  double max_joint_error() const;

 private:
  Scene() = default;
  static void near_callback(void* data, dGeomID a, dGeomID b);
  static void pair_callback(void* data, dGeomID a, dGeomID b);
  void contacts(dGeomID a, dGeomID b);
  void collide();
  std::string name_;
  Stepper stepper_ = Stepper::kQuickStep;
  double length_ = 0.5;
  dWorldID world_ = nullptr;
  dSpaceID space_ = nullptr;
  dJointGroupID contacts_ = nullptr;
  std::vector<dBodyID> bodies_;
  std::vector<dGeomID> geoms_;  ///< every geom (bodies', the plane, the bin's walls)
  std::vector<dJointID> hinges_;
  bool skip_connected_ = false;
  unsigned long shuffle_seed_ = 0;
  std::uint64_t shuffled_steps_ = 0;
  std::vector<std::pair<dGeomID, dGeomID>> pairs_;  ///< shuffle_contacts: a step's pairs
};

}  // namespace tgraph::ode
