// SPDX-License-Identifier: MIT
// An ODE scene run live under a method at K threads, timed pass by pass against ODE
// self-threaded in the same run (`tgraph run --scene ode-*`), and captured into a trace
// (`tgraph capture --scene ode-*`).
#pragma once

#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "tgraph/ode/attach.hpp"
#include "tgraph/ode/method.hpp"

namespace tgraph::ode {

/// What `tgraph run --scene ode-*` does.
struct RunOptions {
  std::string scene;                   ///< ode-piles, ode-heap, ode-chains
  std::optional<std::uint32_t> steps;  ///< default: the scene's
  Method method;
  std::uint32_t threads = 2;
  std::uint32_t repeat = 1;  ///< timed passes of each, interleaved (medians)
  bool check = false;        ///< compare the final state with ODE self-threaded's
  Stepper stepper = Stepper::kQuickStep;
  double watchdog_s = 60.0;
  std::uint32_t repartition_interval = 10;
  partition::Options strategy = {};
  bool json = false;
};

/// A run of `method` on `scene` at `threads` threads, `repeat` timed passes, under `stepper`
/// (`steps` unset: the scene's own); the other fields their defaults. What `tgraph run`,
/// `tgraph validate`, the scaling experiment and the tests start from.
RunOptions run_options(std::string scene, std::optional<std::uint32_t> steps, Method method,
                       std::uint32_t threads, std::uint32_t repeat = 1,
                       Stepper stepper = Stepper::kQuickStep);
/// The attachment each of a run's passes steps through: its method, threads, repartition
/// interval, strategy options and watchdog.
AttachOptions attach_options(const RunOptions& options);

/// One step's medians over the timed passes.
struct RunStep {
  std::int64_t wall_ns = 0;   ///< collision + world step (+ partitioning)
  std::int64_t world_ns = 0;  ///< the world step alone
  std::int64_t collide_ns = 0;
  std::int64_t partition_ns = 0;
  std::int64_t sequential_wall_ns = 0;  ///< ODE self-threaded, same step
  std::int64_t sequential_world_ns = 0;
};

/// A run's outcome.
struct RunResult {
  RunOptions options;
  std::uint32_t steps = 0;
  std::vector<RunStep> per_step;
  std::int64_t wall_ns = 0, world_ns = 0, collide_ns = 0, partition_ns = 0;  ///< median pass
  std::int64_t sequential_wall_ns = 0, sequential_world_ns = 0, sequential_collide_ns = 0;
  std::vector<std::int64_t> pass_wall_ns, sequential_pass_wall_ns;
  double speedup = 0;        ///< sequential_wall_ns / wall_ns: the whole step as the user sees it
  double world_speedup = 0;  ///< sequential_world_ns / world_ns
  AttachStats stats;         ///< the first timed pass (ODE self-threaded's for sequential)
  /// The check: "identical" (bit for bit), "within-rounding" (no position 1e-9 m off),
  /// "within-tolerance" (see `tolerance`) or "differs"; empty: none.
  std::string check;
  double max_abs_diff = 0;  ///< largest difference of a body position (m)
  double max_rel_diff = 0;  ///< largest relative difference of a state number
  /// The tolerance of "within-tolerance" (m): kToleranceBasis (docs/ode.md, "The check").
  double tolerance = 0;
};

/// The one line a run whose check says "differs" fails with: by how much, against which
/// tolerance and its basis (the same basis as `run --json`'s tolerance_basis).
std::string differs_line(const RunResult& r);

/// Runs the scene: `repeat` timed passes under the method, each beside a pass of ODE
/// self-threaded, one warm-up pass of each before; the check from the first passes.
/// InputError for an unknown scene, OptionError for bad options.
RunResult run_scene(const RunOptions& options);

/// The run as one JSON object (the keys of `tgraph run --json`, docs/ode.md).
std::string to_json(const RunResult& r);
/// The run as text.
std::string to_text(const RunResult& r);

/// What `tgraph capture --scene ode-*` does.
struct CaptureOptions {
  std::string scene;
  std::optional<std::uint32_t> steps;
  std::uint32_t threads = 2;  ///< ODE posts as many instances of a stage as it has threads
  Stepper stepper = Stepper::kQuickStep;
  /// Whose steps are recorded: tgraph's runtime under this policy (not `ode`, `sequential`).
  /// islands-serial records whole islands' steps; worksteal and islands ODE's K-thread stages.
  Method method{Policy::kIslandsSerial, ""};
  std::string output;  ///< .tgt
};

/// What a capture did.
struct CaptureReport {
  CaptureOptions options;  ///< as asked
  std::uint32_t steps = 0;
  std::uint64_t tasks = 0, edges = 0, bytes = 0;
  std::int64_t recorded_ns = 0;    ///< the steps recorded (median of 5 passes)
  std::int64_t unrecorded_ns = 0;  ///< the same steps not recorded, alternating, same run
  double overhead = 0;             ///< recorded / unrecorded - 1
};

/// Runs the scene five times without and five times with recording, alternating
/// (`method` at `threads`), and writes the last recorded steps to `output`: one task per
/// part of ODE's calls (docs/ode.md). The recorded passes' logs are made before their timed
/// steps (recording_room).
CaptureReport capture_scene(const CaptureOptions& options);

/// The room `steps` recorded steps of the scene at `threads` under `method` (a policy of
/// tgraph's runtime) took in an untimed recorded pass: AttachOptions::reserve_room for the
/// recorded passes of capture and validate. Between dInitODE2 and dCloseODE.
RecordingRoom recording_room(const std::string& scene, Stepper stepper, std::uint32_t threads,
                             std::uint32_t steps, const Method& method);

/// `tgraph capture --scene ode-* --json`: one object (scene, steps, tasks, edges, bytes,
/// recorded_ns, unrecorded_ns, capture_overhead, output) and a newline.
std::string to_json(const CaptureReport& r);
/// The same as one line of text.
std::string to_text(const CaptureReport& r);

}  // namespace tgraph::ode

namespace tgraph::ode {

/// What `tgraph validate --scene ode-*` does.
struct ValidateOptions {
  std::string scene;
  std::uint32_t steps = 20;
  std::uint32_t threads = 2;
  Method method;             ///< the live run's (worksteal or a partition strategy)
  std::uint32_t repeat = 3;  ///< rounds: live run, capture, prediction; medians
  Stepper stepper = Stepper::kQuickStep;
  std::string calibration;  ///< the simulator's ("": the default one if present)
};

/// One round, measured back to back.
struct ValidateRound {
  std::int64_t live_ns = 0;        ///< the live run's steps under the method
  std::int64_t sequential_ns = 0;  ///< ODE self-threaded, same steps, same round
  std::int64_t predicted_ns = 0;   ///< the simulator's makespans of a capture of those steps
};

/// The simulator's prediction from a capture against the live run.
struct ValidateReport {
  ValidateOptions options;
  std::string strategy;  ///< the strategy whose assignment the simulator schedules
  std::vector<ValidateRound> rounds;
  double live_speedup = 0;         ///< median of sequential / live
  double predicted_speedup = 0;    ///< median of sequential / predicted
  double predicted_over_live = 0;  ///< median of predicted / live (time)
  /// The runtime's own time per call outside its poster's part (taking it, completing it,
  /// its release; trivial calls posted flat on one thread, the time after the posts), charged
  /// by the simulator as `task_overhead_ns` scaled to the captured steps' calls per part.
  double runtime_ns_per_call = 0;
  /// The recording's own time per part (the same calls recorded against not, over their
  /// parts), taken off each captured part's cost before the simulation: the live run records
  /// nothing.
  double recording_ns_per_part = 0;
};

/// The validation of the run `run` describes (its scene, steps or the scene's, method, threads,
/// repeat as rounds, stepper) with the simulator's calibration file.
ValidateOptions validate_options(const RunOptions& run, std::string calibration = {});

/// Each round: the live run (ode::run_scene, one pass), a capture of the same steps at the
/// same threads (worksteal, recording on), and the built-in simulator on each captured step
/// under the method's strategy (`list` for worksteal) at K processors, the step's host time
/// (its collision) as serial work, the runtime's measured time per call as each part's
/// overhead, its spin before parking as the spin budget. OptionError for sequential or ode (no
/// graph to predict).
ValidateReport validate_scene(const ValidateOptions& options);
std::string to_json(const ValidateReport& r);
std::string to_text(const ValidateReport& r);

}  // namespace tgraph::ode
