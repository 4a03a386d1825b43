// SPDX-License-Identifier: MIT
// The engine side of a live run: a step recorded in deferred mode (its graph, bodies and loop
// conditions), the uninstrumented step, the state; and the samples engine behind it.
#pragma once

#include <cstdint>
#include <functional>
#include <memory>
#include <string>
#include <vector>

#include "tgraph/graph/cumulative.hpp"
#include "tgraph/graph/step_graph.hpp"
#include "tgraph/measure/state.hpp"
#include "tgraph/samples/scene.hpp"

namespace tgraph::measure {

/// One step of an engine recorded in deferred mode: nothing has run yet.
struct LiveStep {
  /// True: the engine recorded nothing because this step has the structure of the last one
  /// it recorded (same tasks, same bodies, which read the state through the same pointers):
  /// the runner executes the previous program again (paper section 3.2) and the other
  /// fields are empty.
  bool reuse_previous = false;
  StepGraph graph;                                ///< edges derived, costs may be 0
  std::vector<std::function<void()>> bodies;      ///< by task (empty for a loop's break)
  std::vector<std::function<bool()>> conditions;  ///< by loop: leave after this iteration?
  std::vector<const Accumulator*> accumulators;   ///< by datum, or nullptr
  std::int64_t graph_update_ns = 0;  ///< deriving the graph's edges (part of recording)
};

/// The engine side of a live run (the physics engine behind a small interface; see
/// make_live_engine, the adapter over samples::Scene).
class LiveEngine {
 public:
  virtual ~LiveEngine() = default;
  /// Runs the coordination code of the next step in deferred mode (or, when `allow_reuse`,
  /// reports that the last recorded program applies again: LiveStep::reuse_previous).
  virtual LiveStep record_step(bool allow_reuse) = 0;
  /// Runs the next step uninstrumented, in program order (the sequential engine).
  virtual void plain_step() = 0;
  /// Storage of the state to compare bit for bit (after the steps).
  virtual std::vector<StateRegion> state() const = 0;
};

/// Makes a fresh engine (every pass starts from the scene's initial state).
using EngineFactory = std::function<std::unique_ptr<LiveEngine>()>;

/// A fresh scene stepped through a deferred-mode recorder (record_step) or an uninstrumented
/// one (plain_step); state() lists every datum with storage (positions, velocities, forces,
/// solver vectors and scalars).
///
///   EngineFactory make = [] { return make_live_engine("bars64"); };
///   LiveResult r = run_live(make, &partitioner, options);
std::unique_ptr<LiveEngine> make_live_engine(const std::string& scene,
                                             const samples::SceneOptions& options = {});

}  // namespace tgraph::measure
