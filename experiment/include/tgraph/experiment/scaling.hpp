// SPDX-License-Identifier: MIT
// The scaling experiment: live runs (measure::run_live, as a scene's live run makes them) of
// bars64, falling64, torso and cloth256-s64 for the partition strategies and every baseline
// at each thread count, with where each run's time goes: speed-up, the main thread's serial
// share, inflation of the task bodies, the threads' waiting share, parks, repartitions.
#pragma once

#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "tgraph/experiment/machine.hpp"
#include "tgraph/experiment/progress.hpp"
#include "tgraph/experiment/settings.hpp"
#include "tgraph/explain/explain.hpp"

namespace tgraph::experiment {

/// What to run.
struct ScalingOptions {
  bool quick = false;                   ///< few steps, threads 1,2, a smoke run
  std::string out;                      ///< results folder; "": tgraph-experiment-scaling
  std::vector<std::uint32_t> threads;   ///< thread counts (thread_counts); empty: default
  std::vector<std::string> methods;     ///< strategies and baselines; empty: all
  std::optional<std::uint32_t> steps;   ///< steps of every scene; unset: each scene's own
  std::optional<std::uint32_t> repeat;  ///< timed passes per run (medians); unset: 1
  /// How results.json writes the run that reproduces this one (empty: plain_words).
  InvocationWords words;
  /// Calibration file of the partition runs' predictions; empty: the default calibration
  /// file when there is one, else the defaults.
  std::string calibration;
  /// The scenes (labels: bars64, falling64, torso, cloth256-s64, or an ODE scene ode-piles,
  /// ode-heap, ode-chains in a build with tgraph::ode); empty: the four built-in ones.
  std::vector<std::string> scenes;
};

/// A scene of the sweep with its step count.
struct ScalingScene {
  std::string scene;              ///< built-in scene or ODE scene
  std::optional<int> subobjects;  ///< cloth scenes: sub-objects (a square)
  std::uint32_t steps = 1;
  /// An ODE scene: its runs are ode::run_scene's (ODE self-threaded timed beside each run),
  /// under ScalingPlan::ode_methods.
  bool ode = false;
  /// "bars64", "cloth256-s64".
  std::string label() const;
};

/// The default thread counts on a machine of `cores` cores: the powers of two up to it, and
/// the count of cores itself (12 cores: 1, 2, 4, 8, 12).
std::vector<std::uint32_t> scaling_thread_list(std::uint32_t cores);

/// The runs of the sweep, resolved from the options and the machine.
struct ScalingPlan {
  std::vector<ScalingScene> scenes;
  std::vector<std::string> methods;  ///< strategies (partition policy), then baselines
  /// The ODE scenes' methods (ode::choose_method's names): default sequential (ODE
  /// self-threaded), ode (ODE's own pool), worksteal, islands and list; else the --methods
  /// given.
  std::vector<std::string> ode_methods;
  std::vector<std::uint32_t> threads;
  std::uint32_t repeat = 1;
  std::uint32_t cores = 1;
  bool quick = false;
  std::string out_dir;
  std::vector<std::string> notes;  ///< what the plan left out or warns about, and why
  InvocationWords words;           ///< ScalingOptions::words
  std::string calibration;         ///< ScalingOptions::calibration (checked readable)
  bool scenes_given = false;       ///< ScalingOptions::scenes was not empty
  bool methods_given = false;      ///< ScalingOptions::methods was not empty
  /// Live runs: one per scene, method and thread count, plus one reference run per scene.
  std::size_t runs() const;
  /// The methods a scene runs: ode_methods for an ODE scene, else methods.
  const std::vector<std::string>& methods_of(const ScalingScene& scene) const;
  /// The settings that reproduce this plan (quick, threads, methods, steps when every scene
  /// has the same count, repeat, out).
  Invocation invocation() const;
  /// words_of(words, invocation()): results.json's "command".
  std::string command() const;
};

/// Resolves `options` on a machine with `cores` cores. `scenes` picks the scenes (an ODE scene
/// takes 200 steps, 40 with quick, unless `steps`); a name that is neither a default scene's
/// label nor an ODE scene of this build is an OptionError of "scenes". Defaults: bars64 (20 steps),
/// falling64 (60), torso (60), cloth256-s64 (5); owner, metis, sticky, worksteal, barrier,
/// omp-tasks and starpu (when built); scaling_thread_list(cores); one pass. quick: 2, 3, 3 and 1
/// steps, threads 1,2, methods owner, sticky, worksteal, barrier. tgraph::OptionError names the bad
/// field (an unknown method, sequential or partition as a method, starpu in a build without
/// it, a thread count, steps or repeat of 0).
ScalingPlan plan_scaling(const ScalingOptions& options, std::uint32_t cores);

/// One live run of the sweep. The figures (docs/design.md has them too):
/// - speedup: the scene's sequential wall time (the uninstrumented engine, timed once per
///   scene as run_live times it: the fastest of the first min(threads, 4) cores) over the
///   run's wall time (median of the timed passes);
/// - serial_share: the main thread's record + partition (the time the step waited for it) +
///   prepare, summed over the steps, over that sequential wall time;
/// - inflation: the threads' busy time (task bodies, observed pass) over the same task
///   instances' sequential time (each kind's instances x its mean in the observed sequential
///   pass of the same run);
/// - wait_share: the threads' time outside task bodies (waiting, parked, searching for work,
///   idle) over threads x the executor's wall time, summed over the observed pass's steps
///   (only the partition executor reports its waits apart, so the share counts them all);
/// - parks_per_step: the threads' parks (futex waits) per step, first timed pass;
/// - partitioned_steps: steps at which the partitioner was called, first timed pass (0 for
///   the baselines);
/// - predicted_speedup, predicted_over_live (partition policy): the built-in simulator's
///   makespan of a capture of the same steps with the assignments the live run used (its
///   first timed pass; the strategy's partition of the capture when the capture's steps
///   differ) and the live run's serial work per step, under ScalingOptions::calibration (else
///   the default calibration, else the defaults), against its one-processor makespan with the
///   capture's own host time (the uninstrumented engine, the live speed-up's reference); and that
///   over the live speed-up.
/// An ODE scene's record (ode::run_scene at K threads with its check): speedup and
/// world_speedup against ODE self-threaded timed in the same run (its own passes, interleaved),
/// check and max_abs_diff as `tgraph run --check` says them; serial_share = collision +
/// partitioning over that run's sequential wall time; parks_per_step and partitioned_steps of
/// its first timed pass; inflation, wait_share, the prediction and attribution are not
/// measured (null).
struct ScalingRecord {
  std::string scene;   ///< ScalingScene::label()
  std::string policy;  ///< replay::Policy name
  std::string method;  ///< the strategy under the partition policy, else the policy's name
  std::uint32_t threads = 1;
  double speedup = 0;
  double serial_share = 0;
  double inflation = 0;
  double wait_share = 0;
  double parks_per_step = 0;
  std::uint32_t partitioned_steps = 0;
  /// Partition policy: the built-in simulator's speed-up of the same steps (a capture of
  /// the scene, the assignments the live run used, its serial work per step, the default
  /// calibration; over one processor with the capture's host time), and that over the live
  /// speed-up; 0 for the baselines.
  double predicted_speedup = 0;
  double predicted_over_live = 0;
  /// The observed pass's lost time by cause, summed over the steps (meas::LiveResult's).
  std::optional<explain::Attribution> attribution;
  /// ODE scenes: the world step's speed-up, the check ("identical", "within-rounding",
  /// "within-tolerance", "differs") and the largest position difference (m).
  bool ode = false;
  std::optional<double> world_speedup;
  std::string check;
  double max_abs_diff = 0;
  // Beside the record (results.csv, the text table), not in results.json's `scaling`:
  std::uint32_t steps = 0;
  std::int64_t wall_ns = 0;             ///< median pass
  std::int64_t sequential_wall_ns = 0;  ///< the scene's reference
};

/// A run that was not made or did not finish.
struct ScalingMiss {
  std::string scene, policy, method;
  std::uint32_t threads = 1;
  std::string reason;
};

/// The sequential reference of one scene.
struct ScalingReference {
  std::string scene;
  std::uint32_t steps = 0;
  std::uint32_t cores_timed = 0;        ///< cores the uninstrumented engine was timed on
  std::int64_t sequential_wall_ns = 0;  ///< fastest core's median pass
};

/// Everything the sweep produced.
struct ScalingResult {
  ScalingPlan plan;
  MachineInfo machine;
  std::string date;  ///< UTC, ISO 8601
  double seconds = 0;
  std::vector<ScalingReference> references;
  std::vector<ScalingRecord> records;
  /// Runs the policy refused (StarPU above its CPU workers): not made, with its message.
  std::vector<ScalingMiss> skipped;
  std::vector<ScalingMiss> failed;  ///< runs that threw
  std::vector<std::string> files;   ///< written, in the output folder
};

/// Runs the sweep and writes results.json, results.csv and one speed-up chart per scene
/// (speedup-<scene>.svg/png) into the output folder, atomically; progress lines on
/// `progress`. A run that fails is recorded in `failed` and the others go on.
ScalingResult run_scaling(const ScalingOptions& options, Progress& progress);

/// results.json: `scaling` (the records, with exactly the keys scene, policy, method, threads,
/// speedup, serial_share, inflation, wait_share, parks_per_step, partitioned_steps),
/// `skipped`, `failed`, `references`, the definitions, command, machine, date, files.
std::string scaling_json(const ScalingResult& result, int indent = -1);
/// The table printed on stdout.
std::string scaling_text(const ScalingResult& result);

}  // namespace tgraph::experiment
