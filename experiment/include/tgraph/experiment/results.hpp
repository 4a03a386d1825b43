// SPDX-License-Identifier: MIT
// The rows an experiment produces and their CSV form. Measured figures (live runs and
// synthetic replays on this machine) and predicted ones (the simulator) live in separate
// fields and columns, never in the same one.
#pragma once

#include <cstdint>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

namespace tgraph::experiment {

/// Figures measured on this machine at one thread count (per-step values are means over
/// the run's steps of medians over its timed passes).
struct Measured {
  // Live run (tgraph run): the engine's own bodies through the executor.
  double live_ms_per_step = 0;
  double engine_ms_per_step = 0;        ///< uninstrumented sequential engine, same run
  double live_speedup = 0;              ///< engine / live
  /// The paper's measure, the time integration alone: the captured trace's work (its tasks'
  /// sequential cost) over the live run's task execution time (no recording, collision
  /// detection or other host work). Never mixed with step_speedup.
  double integration_speedup = 0;
  /// The whole step (collision detection and host work included): engine / live.
  double step_speedup = 0;
  double core_bound = 0;                ///< speed-up the timed cores allow (0: not known)
  double record_ms_per_step = 0;        ///< recording the step in deferred mode (edges included)
  double graph_update_ms_per_step = 0;  ///< edge derivation, part of recording
  double partition_ms_per_step = 0;     ///< the partitioner (partition policy)
  double build_ms_per_step = 0;         ///< lowering and plan builds
  std::uint64_t plans_built = 0;
  std::uint64_t structure_changes = 0;  ///< steps recorded afresh after the first
  std::uint64_t signals = 0;            ///< first timed pass
  // Synthetic replay (tgraph replay) of the captured trace, when made.
  std::optional<double> replay_ms_per_step;
  std::optional<double> replay_sequential_ms_per_step;  ///< sequential replay, same run
  std::optional<double> replay_speedup;
};

/// Figures the simulator predicts from the captured trace (partition strategies only).
struct Predicted {
  double speedup = 0;           ///< (work + host) / simulated makespan (= step_speedup)
  /// The time integration alone (the paper's measure): work / (makespan - host).
  double integration_speedup = 0;
  /// The whole step, host work included: (work + host) / makespan.
  double step_speedup = 0;
  double ms_per_step = 0;       ///< simulated makespan
  double work_ms_per_step = 0;  ///< sum of the captured task costs
  double imbalance = 1;         ///< max load / mean load
  std::uint64_t migrated_tasks = 0;
  double partition_ms_per_step = 0;  ///< the strategy on the captured steps
};

/// One configuration: a scene (and its sub-objects), a method, a thread count.
struct ResultRow {
  std::string experiment;
  std::string scene;
  std::optional<int> subobjects;  ///< cloth scenes: sub-objects (empty: the scene's)
  std::string method;             ///< strategy (owner, metis...) or baseline (worksteal...)
  std::string policy;             ///< partition, worksteal, barrier or starpu
  std::uint32_t threads = 1;
  std::optional<Measured> measured;    ///< threads <= cores only
  std::optional<Predicted> predicted;  ///< partition strategies only
  std::string failure;                 ///< why a measurement could not be made
  /// "measured" when the thread count was run on this machine, else "predicted".
  std::string_view threads_kind(std::uint32_t cores) const {
    return threads <= cores ? "measured" : "predicted";
  }
};

/// One step of a live run that repartitions at every step (the heterogeneous experiment).
struct StepRow {
  std::string method;
  std::uint32_t threads = 1;
  std::uint32_t step = 0;
  bool structure_changed = false;  ///< recorded afresh (contacts or groups changed)
  double step_ms = 0;              ///< live step (median over passes)
  double engine_ms = 0;            ///< the same step of the uninstrumented engine
  double record_ms = 0;
  double graph_update_ms = 0;  ///< edge derivation within record_ms (first pass)
  double partition_ms = 0;
  double build_ms = 0;  ///< lowering and plan build (first pass; 0: plan reused)
  double execute_ms = 0;
  std::uint64_t migrated_tasks = 0;  ///< tasks whose processor changed (first pass)
};

/// Column names of results_csv, in order.
std::vector<std::string> result_columns();
/// The rows as CSV (header of result_columns()); measured_* cells are empty for rows
/// whose thread count exceeds `cores`, predicted_* cells empty where nothing was predicted.
std::string results_csv(const std::vector<ResultRow>& rows, std::uint32_t cores);
/// Column names of steps_csv, in order.
std::vector<std::string> step_columns();
/// The per-step rows as CSV.
std::string steps_csv(const std::vector<StepRow>& rows);
/// One CSV cell: quoted (with doubled quotes) when it holds a comma, quote or line break.
std::string csv_cell(std::string_view text);
/// A number for CSV and tables: up to 6 significant digits, no exponent for usual sizes.
std::string number_text(double v);

}  // namespace tgraph::experiment
