// SPDX-License-Identifier: MIT
// The builder of a scene from its directives: scene and solver settings and the common
// attributes in scene_builder.cpp, the objects (particles, springs, grids, rigid bodies,
// chains, cloth) in scene_objects.cpp.
#pragma once

#include <cstdint>
#include <memory>
#include <random>
#include <set>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

#include "scene_reader.hpp"
#include "scene_stability.hpp"
#include "tgraph/samples/scene.hpp"

namespace tgraph::samples::detail {

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

/// Builds a Scene from the directives of a scene file; throws InputError naming the line.
class SceneBuilder {
 public:
  SceneBuilder(std::string file, const SceneOptions& options)
      : file_(std::move(file)), options_(options), jitter_(options.seed) {}

  /// The scene of `text`, checked for stability (check_stability).
  std::unique_ptr<Scene> build(std::string_view text);

 private:
  void directive(Directive& d);
  void solver(Directive& d);
  void collision(Directive& d);
  Body* body_by_name(Directive& d, const std::string& key);
  // Counts `n` more points (nodes, particles, rigid surface points) against
  // SceneOptions::max_nodes before they are built.
  void add_points(Directive& d, std::uint64_t n);
  void check_new_name(Directive& d, const std::string& name);
  // Attributes every body takes: damping, velocity, collision participation.
  void common(Directive& d, Body& b, double spacing);
  // The attributes every object takes: parsed on an array's first instance (`first`),
  // copied to the others.
  void instance_common(Directive& d, Body& b, double spacing, bool first);
  // split=N (or SceneOptions::split): up to N force fields per object (scene_builder.cpp).
  int split_of(Directive& d);
  // `units` in order, cut into up to `split` consecutive runs; make(name, run) builds a field.
  template <class Unit, class Make>
  void add_split_fields(const std::string& name, const std::vector<Unit>& units, int split, Make make);
  std::vector<Index> fixed_nodes(Directive& d, const StateVec& x, const std::string& spec);
  void add_gravity(Body& b);
  void add_fix(Body& b, std::vector<Index> cols);
  // Instances of an object: array=ax,ay,az spacing=dx,dy,dz, each jittered by jitter=a.
  std::vector<std::pair<std::string, Vec3>> instances(Directive& d, const std::string& name, const Vec3& center);

  // The objects (scene_objects.cpp).
  void particles(Directive& d);
  void springs(Directive& d);
  void grid_object(Directive& d);
  void rigid(Directive& d);
  void chain(Directive& d);
  void cloth(Directive& d);

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

}  // namespace tgraph::samples::detail
