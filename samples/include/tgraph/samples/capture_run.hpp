// SPDX-License-Identifier: MIT
// Driving the engine for a capture: a scene stepped N times through a Recorder, every step
// streamed to a .tgt trace, with per-step figures; and the trace header of a scene.
#pragma once

#include <cstdint>
#include <functional>
#include <optional>
#include <stdexcept>
#include <string>
#include <vector>

#include "tgraph/graph/access_check.hpp"
#include "tgraph/graph/error.hpp"
#include "tgraph/graph/trace.hpp"
#include "tgraph/samples/scene.hpp"

namespace tgraph::samples {

/// What to capture (the capture verb binds its flags to these fields).
struct CaptureOptions {
  std::string scene;           ///< built-in scene name or scene file
  std::optional<int> steps;    ///< default: the scene's
  std::string output;          ///< .tgt to write; required unless `no_capture`
  SceneOptions scene_options;  ///< dt, seed, sub-objects, coupling
  bool no_capture = false;     ///< run uninstrumented (Mode::kOff), write nothing
  bool progress = false;       ///< a progress line on stderr
  /// Timed passes of every task body, median kept (Recorder::set_cost_passes; 1: one run).
  std::uint32_t cost_passes = 1;
  /// Write steps in which the recorder saw API misuses (Recorder::step_errors) instead of
  /// stopping before the first of them; the misuses are then reported as a warning.
  bool allow_misuse = false;
  /// Verify every task's declared accesses as it runs (Recorder::set_verify_accesses):
  /// CaptureRun::access_findings lists the wrong declarations.
  bool verify_accesses = false;
  /// Called with each of the scene's warnings (unstable dt...) before the first step; a
  /// warning names the options' fields as `{field}` (name_fields writes them in one's words).
  std::function<void(const std::string&)> warn;
};

/// What a capture did.
struct CaptureRun {
  std::string scene;
  std::string mode;  ///< "capture" or "off"
  int steps = 0;
  double seconds = 0.0;     ///< engine time (steps, recording included)
  std::uint64_t tasks = 0;  ///< over all steps
  std::uint64_t file_bytes = 0;
  double dt = 0.0;
  std::size_t bodies = 0;
  std::vector<double> step_ms;
  std::vector<std::uint32_t> cg_iterations;
  std::vector<std::uint32_t> groups;  ///< collision groups after each step
  std::uint32_t cost_passes = 1;      ///< CaptureOptions::cost_passes
  /// Task runs timed once despite cost passes (Recorder::single_pass_runs).
  std::uint64_t single_pass_runs = 0;
  /// API misuses the recorder counted (written anyway: CaptureOptions::allow_misuse).
  std::uint64_t misuses = 0;
  /// CaptureOptions::verify_accesses: the wrong declarations found (empty: none).
  std::vector<AccessFinding> access_findings;
  /// CaptureOptions::verify_accesses: task runs checked, reruns, runs whose reads were not
  /// checked (they write a datum without storage).
  AccessChecker::Counts access_counts;
};

/// The work of a capture failed (a diverging simulation, a failed write, API misuse): the
/// message says what and where the complete steps before it are, readable with
/// ReadOptions::recover, which it names as the field `{recover}` (exit status 1).
class CaptureFailure : public ErrorWithFields {
 public:
  using ErrorWithFields::ErrorWithFields;
};

/// Runs the capture. Bad options or scene: tgraph::Error; failure of the run: CaptureFailure
/// (the steps written before stay in `<output>.partial`, readable with ReadOptions::recover).
///
///   CaptureRun r = capture_scene({.scene = "bars64", .steps = 20, .output = "b.tgt"});
CaptureRun capture_scene(const CaptureOptions& options);

/// The JSON of a capture: one object.
std::string capture_json(const CaptureRun& run, const CaptureOptions& options);
/// A capture's one-line text report.
std::string capture_text(const CaptureRun& run, const CaptureOptions& options);

/// Header of a trace captured from `scene` (engine, integrator, dt, seed, this machine).
TraceHeader scene_header(const Scene& scene, std::uint64_t seed);

}  // namespace tgraph::samples
