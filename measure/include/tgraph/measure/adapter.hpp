// SPDX-License-Identifier: MIT
// An engine from outside the tree in a live run: its coordination code behind LiveEngine in a
// few lines, and one call that runs it on K threads, checks it against a sequential run and
// times it (docs/instrumenting.md, "Run it live").
#pragma once

#include <cstdint>
#include <functional>
#include <memory>
#include <string>
#include <utility>
#include <vector>

#include "tgraph/capture/recorder.hpp"
#include "tgraph/measure/engine.hpp"
#include "tgraph/measure/live.hpp"
#include "tgraph/measure/method.hpp"
#include "tgraph/measure/report.hpp"
#include "tgraph/measure/state.hpp"

namespace tgraph::measure {

/// One fresh engine as a live run needs it. The same coordination code serves both ways of
/// stepping: issued to a deferred-mode Recorder, a step's tasks are recorded with their bodies
/// and an executor runs them on its threads; issued to an off-mode Recorder, the bodies run at
/// once, in program order (the sequential engine the live run is timed and checked against).
///
///   CallbacksFactory make = [] {
///     auto e = std::make_shared<MyEngine>();  // a fresh engine: every pass starts afresh
///     return EngineCallbacks{.declare = [e](capture::Recorder& rec) { e->declare(rec); },
///                            .step = [e](capture::Recorder& rec) { e->issue_tasks(rec); }};
///   };
///   LiveOptions o;
///   o.exec.threads = 2;
///   o.check = true;
///   LiveResult r = run_engine_live(make, choose_method("owner"), o);
///   std::puts(to_json(r, "my engine", "owner").c_str());  // as a scene's live run reports
struct EngineCallbacks {
  /// Declares the engine's kinds, objects and data (each with its storage) on `rec`; called
  /// once, before the first step. The ids it hands out are the ones `step` uses.
  std::function<void(capture::Recorder& rec)> declare;
  /// Issues one step's tasks to `rec` (and its loops); the adapter calls rec.begin_step()
  /// before and ends the step after. Every computation belongs in a task body.
  std::function<void(capture::Recorder& rec)> step;
  /// The state compared bit for bit after the steps, in a fixed order. Optional: without it,
  /// every datum declared with storage, in declaration order.
  std::function<std::vector<StateRegion>()> state;
  /// Every step issues the same tasks, whose bodies reach the state through the same pointers:
  /// the run records the first step only and runs its program again (LiveStep::reuse_previous;
  /// `step` is then not called for the later steps).
  bool same_every_step = false;
};

/// Makes the callbacks of a fresh engine.
using CallbacksFactory = std::function<EngineCallbacks()>;

/// The engine of `callbacks` behind LiveEngine. Its Recorder is made at the first call, in
/// deferred mode for record_step and in off mode for plain_step; an engine is stepped one way
/// only (a call of the other kind throws UsageError), as run_live does. record_step throws
/// UsageError naming the count when the recorder counted API misuses.
std::unique_ptr<LiveEngine> make_live_engine(EngineCallbacks callbacks);

/// Runs `options.steps` steps of fresh engines from `make` live (run_live) under `method`: a
/// partitioning strategy under the partition policy (partitioned again when the structure
/// changes or the measured costs unbalance it, sticky's threshold live_sticky_threshold) or a
/// baseline policy. `options.policy` is set from `method`; the other fields are used as given
/// (threads in options.exec.threads; options.check compares the final state with a
/// sequential run bit for bit). UsageError for an unknown strategy.
LiveResult run_engine_live(const CallbacksFactory& make, const MethodChoice& method,
                           LiveOptions options);

/// A live run's JSON object for an outside engine (to_json(r, engine, method) of
/// report.hpp: `engine` under the key "scene") with `extra` numeric keys added, such as an
/// engine's own check of its result.
std::string to_json(const LiveResult& r, const std::string& engine, const std::string& method,
                    const std::vector<std::pair<std::string, double>>& extra);

}  // namespace tgraph::measure
