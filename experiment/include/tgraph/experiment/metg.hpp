// SPDX-License-Identifier: MIT
// The METG experiment: Task Bench's minimum effective task granularity (Slaughter et al.,
// SC'20) for every replay policy, on synthetic graphs of Task Bench's dependence patterns and
// on bars64's own step, at every thread count of the machine.
#pragma once

#include <cstdint>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "tgraph/experiment/machine.hpp"
#include "tgraph/experiment/progress.hpp"
#include "tgraph/experiment/settings.hpp"
#include "tgraph/graph/step_graph.hpp"

namespace tgraph::experiment {

/// Dependence patterns swept by the METG experiment.
enum class MetgShape : std::uint8_t {
  kTrivial = 0,        ///< Task Bench "trivial": no dependences
  kStencil = 1,        ///< "stencil_1d": point i at step t reads i-1, i, i+1 at t-1
  kFft = 2,            ///< "fft": butterfly, i and i xor 2^s at t-1 (s cycles over the stages)
  kRandomNearest = 3,  ///< "random_nearest": i and a seeded random subset of i-2..i+2 at t-1
  kBars64 = 4,         ///< bars64's captured first step (CG loop included), every task one size
};

/// "trivial", "stencil", "fft", "random_nearest" or "bars64".
std::string_view to_string(MetgShape shape);

/// One step of `width` x `steps` tasks of `task_ns` each in `shape` (not kBars64): task
/// (t, i) writes its own datum and reads those of its dependences at step t - 1; object i
/// holds point i (the owner strategy keeps a point's chain on one processor).
StepGraph metg_graph(MetgShape shape, std::uint32_t width, std::uint32_t steps,
                     std::uint64_t task_ns);

/// What to run.
struct MetgOptions {
  bool quick = false;    ///< coarse duration grid, one timed pass, small graphs
  std::string out;                     ///< results folder; "": tgraph-experiment-metg
  std::vector<std::uint32_t> threads;  ///< thread counts (thread_counts); empty: 1 to the cores
  /// The replay policies swept (the other experiments' methods); empty: sequential and every
  /// parallel policy built.
  std::vector<std::string> methods;
  /// How results.json writes the run that reproduces this one (empty: plain_words).
  InvocationWords words;
};

/// One timed point: a policy on a shape at a thread count and a task duration.
struct MetgPoint {
  std::string policy;
  std::string shape;
  std::uint32_t threads = 1;
  std::uint64_t task_ns = 0;      ///< the duration of every task
  std::uint64_t instances = 0;    ///< task instances per step (loop iterations unrolled)
  std::int64_t wall_ns = 0;       ///< median step wall time
  /// The sequential policy's wall time on the same step, same durations, same run, over
  /// threads x wall_ns: the efficiency METG is computed from (1 for the sequential policy).
  double efficiency = 0;
  /// Task Bench's own reference, the work the spins were calibrated to do: instances x
  /// task_ns / (threads x wall_ns) (the calibration is only as good as this machine is quiet).
  double work_efficiency = 0;
  std::uint64_t granularity_ns = 0;  ///< threads x wall_ns / instances (Task Bench)
};

/// METG(50 %) of one policy on one shape at one thread count.
struct MetgRecord {
  std::string policy;
  std::string shape;
  std::uint32_t threads = 1;
  /// The smallest granularity (threads x wall / tasks) among the points whose efficiency is
  /// at least 50 % (Task Bench's METG); nullopt when no swept duration reached 50 %.
  std::optional<std::uint64_t> metg_ns;
  std::uint64_t task_ns = 0;  ///< the task duration of that point
  double efficiency = 0;      ///< its efficiency
};

/// Everything the METG experiment produced.
struct MetgResult {
  MetgOptions options;
  MachineInfo machine;
  std::string date;
  double seconds = 0;
  std::vector<std::uint32_t> threads;
  std::vector<std::string> policies;
  std::vector<std::string> shapes;
  std::vector<MetgPoint> points;
  std::vector<MetgRecord> records;  ///< every (policy, shape, threads) run
  /// Why some (policy, threads) were not run (StarPU above its build's CPU workers).
  std::vector<std::string> skipped;
  std::vector<std::string> files;
  /// The settings that reproduce this run (quick, threads and methods when given, out).
  Invocation invocation() const;
  /// words_of(options.words, invocation()): results.json's "command".
  std::string command() const;
};

/// Runs the sweep and writes results.json, results.csv and one efficiency chart per shape
/// (efficiency-<shape>.svg/png) into the output folder, atomically. Bad options: OptionError.
MetgResult run_metg(const MetgOptions& options, Progress& progress);

/// results.json: `metg` (the records reaching 50 %: policy, shape, threads, metg_ns, task_ns,
/// efficiency), `unreached` (the others), `skipped` (why a policy did not run at some thread
/// counts), `points`, the definition, machine, date, files.
std::string metg_json(const MetgResult& result, int indent = -1);
/// The METG table printed on stdout.
std::string metg_text(const MetgResult& result);

}  // namespace tgraph::experiment
