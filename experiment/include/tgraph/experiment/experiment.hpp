// SPDX-License-Identifier: MIT
// The paper's experiments (Hermann, Raffin, Faure, EGPGV 2009, section 4), one command each:
// live runs of the built-in scenes on every thread count this machine has (the uninstrumented
// engine timed in the same run as the reference), synthetic replays of the captured trace,
// and the simulator's predictions for larger thread counts, written as CSV, JSON, an HTML
// report and SVG/PNG charts.
#pragma once

#include <cstdint>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "tgraph/experiment/machine.hpp"
#include "tgraph/experiment/progress.hpp"
#include "tgraph/experiment/results.hpp"
#include "tgraph/experiment/settings.hpp"
#include "tgraph/experiment/threads.hpp"

namespace tgraph::experiment {

/// The experiments of the paper's section 4.
enum class ExperimentName : std::uint8_t {
  kIndependent = 0,    ///< Fig. 5: bars64, 64 independent FEM bars
  kHeterogeneous = 1,  ///< Fig. 6 and 8: falling, objects colliding into one group
  kDomain = 2,         ///< Fig. 7: cloth128/256/512 cut into sub-objects
  kMedical = 3,        ///< section 4.4: torso
};

/// "independent", "heterogeneous", "domain" or "medical".
std::string_view to_string(ExperimentName name);
/// Inverse of to_string; nullopt for another name.
std::optional<ExperimentName> parse_experiment_name(std::string_view name);
/// The four names, in the paper's order.
std::vector<std::string> experiment_names();
/// Every experiment run_named runs: the paper's four, then "metg" and "scaling".
std::vector<std::string> all_experiment_names();

/// What to run; empty or unset fields take the experiment's defaults (plan_experiment).
struct ExperimentOptions {
  ExperimentName name = ExperimentName::kIndependent;
  std::vector<std::uint32_t> threads;   ///< thread counts (thread_counts); empty: default
  std::string out;                      ///< results folder; "": tgraph-experiment-<name>
  bool quick = false;                   ///< fewer steps, one pass, fewer variants
  std::optional<std::uint32_t> steps;   ///< steps per run
  std::optional<std::uint32_t> repeat;  ///< timed passes per run (medians)
  std::vector<std::string> methods;     ///< strategies and baselines; empty: the experiment's
  std::vector<int> subobjects;          ///< domain: sub-object counts (squares); empty: default
  std::optional<bool> replay;           ///< synthetic replays too; unset: the experiment's default
  /// How the results files write the run that reproduces this one (empty: plain_words).
  InvocationWords words;
  /// Calibration file of the predictions (`tgraph calibrate --out`); empty: the default
  /// calibration file when there is one, else the defaults. Not for metg (no prediction).
  std::string calibration;
  /// scaling: the scenes (ScalingOptions::scenes); empty: the experiment's.
  std::vector<std::string> scenes;
};

/// A scene with its build options.
struct SceneVariant {
  std::string scene;
  std::optional<int> subobjects;
  /// "bars64", "cloth256-s16" (file names, labels).
  std::string label() const;
};

/// The runs an experiment makes, resolved from the options and the machine.
struct ExperimentPlan {
  ExperimentName name = ExperimentName::kIndependent;
  std::vector<SceneVariant> scenes;
  std::vector<std::string> methods;         ///< strategies and baselines, in table order
  std::vector<std::string> series_methods;  ///< repartitioned every step (heterogeneous)
  std::uint32_t series_threads = 1;         ///< thread count of those runs
  std::uint32_t steps = 1;
  std::uint32_t repeat = 1;
  /// Synthetic replays of the captured trace beside the live runs (see replays()).
  bool replay = false;
  std::uint32_t cores = 1;
  ThreadPlan threads;
  std::string out_dir;
  std::vector<std::string> notes;  ///< what the plan left out and why
  InvocationWords words;           ///< ExperimentOptions::words
  std::string calibration;         ///< ExperimentOptions::calibration (checked readable)
  /// Whether `method` at `threads` is replayed: when replays are on, at more than one thread
  /// (one thread replays the sequential order), and not for starpu (its replay costs 4 to 7
  /// times the sequential one; docs/results.md has it).
  bool replays(const std::string& method, std::uint32_t threads) const;
  /// Runs reported on the progress line (live runs, replays, per-step runs).
  std::size_t runs() const;
  /// The settings that reproduce this plan (every one resolved: threads, steps, repeat,
  /// methods, domain's subobjects, replay, out).
  Invocation invocation() const;
  /// words_of(words, invocation()): the results files' "command".
  std::string command() const;
};

/// Resolves `options` on a machine with `cores` cores; tgraph::OptionError names the bad
/// field (unknown method, starpu in a build without it, sub-objects outside `domain`, a
/// sub-object count that is not a perfect square, a thread count, steps or repeat of 0).
ExperimentPlan plan_experiment(const ExperimentOptions& options, std::uint32_t cores);

/// What the paper reports for an experiment, for the report beside ours.
struct PaperFigure {
  std::string figure;  ///< "Fig. 5"
  std::string text;    ///< its scene, machine, sequential time and speed-up, in one paragraph
  /// Sequential time of one step on the paper's machines, by scene (ms).
  std::vector<std::pair<std::string, double>> sequential_ms;
};

/// The paper's figure for `name` (section 4).
PaperFigure paper_figure(ExperimentName name);

/// Summary of one method's per-step run (heterogeneous).
struct SeriesSummary {
  std::string method;
  std::uint32_t threads = 1;
  std::uint32_t steps = 0;
  std::uint32_t structure_changes = 0;  ///< steps recorded afresh after the first
  double step_ms = 0;                   ///< mean live step
  double engine_ms = 0;                 ///< mean uninstrumented step
  double partition_ms = 0;              ///< mean per step
  double build_ms = 0;                  ///< mean per step: lowering and plan builds
  std::uint64_t migrated_tasks = 0;     ///< over the run
  /// Mean over the changed steps (step 0 excluded) of graph update + plan build, and of
  /// record + partition + build (the whole cost of a new graph).
  double update_ms_changed = 0;
  double new_graph_ms_changed = 0;
};

/// Everything an experiment produced.
struct ExperimentResult {
  ExperimentPlan plan;
  MachineInfo machine;
  std::string date;    ///< UTC, ISO 8601
  double seconds = 0;  ///< wall time of the whole experiment
  /// The cost model of the predictions: "defaults" (no calibration file) or the path of the
  /// calibration file read.
  std::string cost_model;
  std::vector<ResultRow> rows;
  std::vector<StepRow> steps;
  std::vector<SeriesSummary> series;
  std::vector<std::string> files;  ///< written, in the output folder
  /// Runs that failed (their rows say why).
  std::size_t failures() const;
};

/// Runs the experiment and writes results.csv, results.json, report.html, speedup.svg and
/// speedup.png (heterogeneous: steps.csv and steps-*.svg/png too) and the captured traces
/// into the output folder, every file atomically. Progress goes to `progress`. A run that
/// fails is recorded in its row and the others go on.
ExperimentResult run_experiment(const ExperimentOptions& options, Progress& progress);

/// results.json: plan, machine, date, paper figure, rows (measured and predicted as
/// separate objects), per-step rows and summaries, files. `indent` < 0: one line.
std::string experiment_json(const ExperimentResult& result, int indent = -1);
/// The summary printed on stdout: one table per scene, the per-step summaries, the files.
std::string experiment_text(const ExperimentResult& result);

/// What an experiment of run_named produced, as `tgraph experiment` prints it.
struct NamedRun {
  std::string text;          ///< experiment_text, metg_text or scaling_text
  std::string json;          ///< results.json on one line
  std::size_t failures = 0;  ///< runs that failed
};

/// Runs the experiment `name` (one of all_experiment_names()): the paper's through
/// run_experiment; metg (run_metg) takes quick, threads, out and methods (its policies);
/// scaling (run_scaling) those and steps and repeat. OptionError on `subobjects` or `replay`
/// where the experiment does not take them.
NamedRun run_named(std::string_view name, const ExperimentOptions& options, Progress& progress);

}  // namespace tgraph::experiment
