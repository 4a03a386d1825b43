// SPDX-License-Identifier: MIT
// The verbs of the `tgraph` command line. Each verb lives in its own cmd_<verb>.cpp and
// only parses flags and calls the modules.
#pragma once

#include <CLI/CLI.hpp>
#include <algorithm>
#include <cstdint>
#include <iostream>
#include <nlohmann/json.hpp>
#include <optional>
#include <stdexcept>
#include <string>
#include <thread>
#include <vector>

#include "tgraph/graph/error.hpp"
#include "tgraph/graph/file_util.hpp"
#include "tgraph/graph/trace.hpp"
#include "tgraph/graph/trace_io.hpp"
#include "tgraph/samples/capture_run.hpp"

namespace tgraph::partition {
struct NamedOptions;
}  // namespace tgraph::partition

namespace tgraph::app {

/// The work itself failed (exit 1), as opposed to bad input (tgraph::Error, exit 2).
class Failure : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

/// Values of a verb's flags that no module's option struct holds (each verb owns one; module
/// options such as partition::NamedOptions or replay::LiveOptions hold the rest).
struct Args {
  std::string input, assignment, output, method, policy, format, cw, timeline, chrome, csv;
  std::string compare, range, collapse = "none";
  std::vector<std::string> names;
  std::vector<std::uint32_t> counts;
  std::vector<double> values;
  std::optional<int> steps;
  std::optional<int> split;  ///< run --split: force-field tasks per deformable object
  std::size_t step = 0;
  std::uint32_t k = 0;
  std::uint64_t unit_ns = 1000, edge_bytes = 8;
  bool json = false, recover = false;
};

/// `--live RUN.json` | `--serial-ns N` of evaluate and simulate: the main thread's serial work
/// per step that the simulation charges instead of the trace's host time.
struct SerialFlags {
  std::string live;                        ///< a `tgraph run --json` output
  std::optional<std::uint64_t> serial_ns;  ///< the same for every step
  /// The per-step values for a trace of `steps` steps (empty: neither flag); UsageError when
  /// the run has fewer steps than the trace.
  std::vector<std::uint64_t> per_step(std::size_t steps) const;
};
/// Adds `--live` and `--serial-ns` to `cmd`.
void add_serial_flags(CLI::App* cmd, SerialFlags& f);

/// Prints "tgraph: warning: TEXT" on stderr (what the user should know; not an error).
inline void warn(const std::string& text) { std::cerr << "tgraph: warning: " << text << '\n'; }
/// Prints a JSON object on stdout (one line, as `--json` promises).
inline void print_json(const nlohmann::json& j) { std::cout << j.dump() << std::endl; }
/// Threads a verb uses by default: all hardware threads (at least 1).
inline std::uint32_t default_threads() { return std::max(1u, std::thread::hardware_concurrency()); }
/// Header of a trace captured from a scene (samples).
using samples::scene_header;

// Registration of each verb (one function per cmd_*.cpp).
void add_info(CLI::App& app);
void add_export(CLI::App& app);
void add_diff(CLI::App& app);
void add_capture(CLI::App& app);
void add_generate(CLI::App& app);
void add_demo(CLI::App& app);
void add_experiment(CLI::App& app);
void add_partition_verbs(CLI::App& app);  // partition, evaluate, compare, import, calibrate
/// The partitioning flags of `partition`, `compare` and `run` (strategy, phases, cost model).
void add_strategy_flags(CLI::App* cmd, partition::NamedOptions& n);
void add_replay_verbs(CLI::App& app);     // replay, run
void add_validate(CLI::App& app);         // validate (live vs replay vs simulator)
void add_viz_verbs(CLI::App& app);        // viz, then add_timeline and add_report
void add_timeline(CLI::App& app);
void add_report(CLI::App& app);
void add_simulate(CLI::App& app);         // simulate (builtin or SimGrid)
void add_platform(CLI::App& app);         // platform (SimGrid platform file)

/// Every verb, in the order `tgraph --help` lists them (main() and the command-line fuzz
/// target register the same set).
inline void add_all_verbs(CLI::App& app) {
  add_demo(app);
  add_experiment(app);
  add_capture(app);
  add_generate(app);
  add_info(app);
  add_export(app);
  add_diff(app);
  add_partition_verbs(app);
  add_simulate(app);
  add_platform(app);
  add_replay_verbs(app);
  add_validate(app);
  add_viz_verbs(app);
}

}  // namespace tgraph::app
