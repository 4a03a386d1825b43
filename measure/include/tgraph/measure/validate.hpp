// SPDX-License-Identifier: MIT
// `tgraph validate`: the live run of a scene (the truth), the synthetic replay of a capture of
// the same steps and the simulator's prediction of the same partition, side by side.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "tgraph/graph/assignment.hpp"
#include "tgraph/graph/trace.hpp"
#include "tgraph/measure/method.hpp"
#include "tgraph/samples/scene.hpp"

namespace tgraph::measure {

struct LiveResult;  // tgraph/measure/live.hpp

/// What to validate.
struct ValidateOptions {
  std::string scene;
  samples::SceneOptions scene_options;  ///< the scene's overrides (split), live and captured
  MethodChoice method;  ///< a strategy under the partition policy, or a baseline policy
  std::uint32_t threads = 1;
  std::uint32_t steps = 20;
  std::uint32_t repeat = 3;  ///< rounds (live pass, capture, replay pass, simulation); medians
  /// The simulator's calibration file ("": the default one if present, else the defaults).
  std::string calibration;
  /// Charge the live run's serial work per step (record + partition wait + prepare) in the
  /// prediction instead of the capture's host time.
  bool live_serial = true;
};

/// One task kind's slow-down in parallel: the live run's (its observed pass's mean duration
/// over the observed sequential pass's) beside the simulator's (the kind's simulated body
/// time, inflated, over the capture's costs).
struct KindInflation {
  std::string kind;
  std::uint64_t instances = 0;  ///< the live observed pass's
  double live = 0;              ///< 0: no sequential mean to compare with
  double predicted = 0;         ///< 0: the capture has no instance of the kind
  double live_mean_ns = 0;        ///< an instance's mean time in the policy's observed pass
  double sequential_mean_ns = 0;  ///< the same in the sequential observed pass
  double captured_mean_ns = 0;    ///< the capture's cost per instance (0: no instance)
};

/// One round of a validation: the three measured back to back, so that a machine whose
/// speed drifts (a shared VM) moves all three alike and their ratios stay comparable.
struct ValidationRound {
  std::int64_t live_ns = 0;        ///< live run, one pass
  std::int64_t engine_ns = 0;      ///< uninstrumented engine, same round
  std::int64_t replay_ns = 0;      ///< synthetic replay of this round's capture, one pass
  std::uint64_t predicted_ns = 0;  ///< simulator on this round's capture (0: no partition)
  std::uint64_t host_ns = 0;       ///< the capture's host time (outside the graph)
  std::uint64_t serial_ns = 0;     ///< the live run's serial work the prediction charged
  /// Sequential pass of the same replay, same round (its speed-up's denominator).
  std::int64_t replay_sequential_ns = 0;
  /// The simulator on one processor (the capture's costs and host time, no synchronisation:
  /// the simulated uninstrumented engine, as `engine_ns` is the live speed-up's): the
  /// predicted speed-up's denominator (0: no partition).
  std::uint64_t predicted_sequential_ns = 0;
  /// Where the threads' time went in the steps' task phase, summed over the steps and the
  /// threads or processors (partition policy only; 0 otherwise). Live, from the observed
  /// pass (every body timed): time in bodies, in blocked waits, and the rest (idle: the
  /// executor's and the observers' own time between bodies). Predicted: the simulated
  /// instances' costs (inflated) and the interruptions inside them (a live body's clock
  /// sees those); the processors' time waiting (the task phase less their busy time); the
  /// executor's time per task and the transfers.
  std::int64_t live_body_ns = 0, live_wait_ns = 0, live_idle_ns = 0;
  std::uint64_t predicted_body_ns = 0, predicted_wait_ns = 0, predicted_overhead_ns = 0;
  /// The bodies' slow-down over all kinds, weighted by their sequential time: live (the
  /// observed passes) and predicted (the simulator's inflation); 0: not measured.
  double live_inflation = 0, predicted_inflation = 0;
  std::vector<KindInflation> kinds;  ///< by kind (partition policy only)
};

/// The three figures of one validation: medians over the rounds, and the medians of each
/// round's own ratios.
struct Validation {
  MethodChoice choice;
  std::uint32_t threads = 1;
  std::vector<ValidationRound> rounds;
  std::int64_t live_ns = 0, engine_ns = 0, replay_ns = 0;
  std::uint64_t predicted_ns = 0;  ///< simulator, partition policy only (0: none)
  double replay_over_live = 0, predicted_over_live = 0, predicted_over_replay = 0;
  /// Speed-ups, each over its own sequential pass of the same round (live: the
  /// uninstrumented engine; replay: the sequential replay; simulator: one processor), and
  /// the medians of each round's predicted or replayed speed-up / live speed-up. Unlike the
  /// times' ratios these do not move when the machine's pace drifts between the capture,
  /// whose costs the two models use, and the live run (a shared VM's does by 10-20 % within
  /// seconds: predicted / live at 1 thread, where the model is the costs' sum, spread
  /// 0.82-1.01 over three rounds on bars64).
  double live_speedup = 0, replay_speedup = 0, predicted_speedup = 0;
  double replay_speedup_over_live = 0, predicted_speedup_over_live = 0;
  std::string model;                     ///< the cost model's source
  std::vector<std::string> model_terms;  ///< what the prediction charged
  /// Partition policy: the rounds whose replay and prediction ran the assignments the live
  /// run used, step by step (carried-over steps included); the others (a capture whose
  /// steps do not match the live run's) ran the strategy's offline partition of the capture.
  std::uint32_t rounds_with_live_assignments = 0;
  /// Partition policy: the medians over the rounds of each round's predicted / live time in
  /// bodies and in waits, of its live and predicted inflation, and per kind of the two
  /// slow-downs (the first round's kinds): which part of the prediction departs from the
  /// live run (0 and empty for the other policies).
  double body_predicted_over_live = 0, wait_predicted_over_live = 0;
  double live_inflation = 0, predicted_inflation = 0;
  std::vector<KindInflation> kinds;
};

// The pieces of a live run's prediction (`validate`'s, `experiment scaling`'s).

/// The main thread's serial work of each step of live run `r` (record + partition + prepare).
std::vector<std::uint64_t> live_serial_work(const LiveResult& r);
/// The assignments a prediction of `capture` simulates for a partition run of `method` on
/// `k` threads: the live run's (`ran`, one per step) when they assign every step of the
/// capture task for task (`*live` true), else the strategy's partition of the capture.
TraceAssignment live_assignment(const Trace& capture, const std::vector<Assignment>& ran,
                                const std::string& method, std::uint32_t k, bool* live);
/// Every task of every step of `trace` on one processor.
TraceAssignment one_processor(const Trace& trace);
/// How long the partition executor's waits spin before parking on `k` threads with its
/// ExecOptions::spin_ns: up to replay::kLongSpinNs where every thread has a core of its own.
double live_spin_budget_ns(std::uint32_t k, std::int64_t spin_ns);

/// Runs `repeat` rounds of: the live run (one pass, against the uninstrumented engine), a
/// capture of the same steps, its replay under the same policy (one pass) and the
/// simulation of the partition. OptionError for zero threads (but for the sequential
/// policy), steps or repeat; UsageError for an unknown method.
Validation validate(const ValidateOptions& options);

}  // namespace tgraph::measure
