// SPDX-License-Identifier: MIT
// The verbs of `tgraph`: each cmd_<verb>.cpp binds flags, calls the modules and prints.
#pragma once

#include <CLI/CLI.hpp>
#include <algorithm>
#include <cstdint>
#include <initializer_list>
#include <iostream>
#include <stdexcept>
#include <string>
#include <thread>
#include <vector>

#include "tgraph/graph/error.hpp"
#include "tgraph/graph/file_util.hpp"
#include "tgraph/graph/trace.hpp"
#include "tgraph/graph/trace_io.hpp"
#include "tgraph/model/cost_model.hpp"
#include "tgraph/partition/strategy.hpp"

namespace tgraph::app {

/// The work itself failed (exit 1), as opposed to bad input (tgraph::Error, exit 2).
struct Failure : std::runtime_error {
  using std::runtime_error::runtime_error;
};

/// Values of a verb's flags that no module's option struct holds (each verb owns one).
struct Args {
  std::string input, assignment, output, method, policy, format, timeline, chrome, csv;
  std::string compare, range;
  std::vector<std::string> names;
  std::vector<std::uint32_t> counts;
  std::vector<double> values;
  std::size_t step = 0;
  std::uint32_t k = 0, steps = 1;
  std::uint64_t unit_ns = 1000, edge_bytes = 8;
  bool json = false, recover = false;
};

/// Adds `--live` and `--serial-ns` of evaluate and simulate to `cmd`.
void add_serial_flags(CLI::App* cmd, model::SerialWork& w);
/// Adds `--model` and `--calibration` (partition::NamedOptions::cost_model) to `cmd`.
void add_model_flags(CLI::App* cmd, partition::NamedOptions& n);
/// Adds `flag` to `cmd`, bound to the enum `out` (or an optional one): one of `values` by its
/// to_string name; CLI::IsMember refuses any other.
template <class T, class E>
CLI::Option* add_enum(CLI::App* cmd, const std::string& flag, T& out,
                      std::initializer_list<E> values, const std::string& help) {
  std::vector<std::string> names;
  for (E v : values) names.emplace_back(to_string(v));
  const auto set = [&out, names, all = std::vector<E>(values)](const std::string& name) {
    out = all[static_cast<std::size_t>(std::find(names.begin(), names.end(), name) -
                                       names.begin())];
  };
  return cmd->add_option_function<std::string>(flag, set, help)->check(CLI::IsMember(names));
}

/// Prints "tgraph: warning: TEXT" on stderr (what the user should know; not an error).
inline void warn(const std::string& text) { std::cerr << "tgraph: warning: " << text << '\n'; }
/// Threads a verb uses by default: all hardware threads (at least 1).
inline std::uint32_t default_threads() { return std::max(1u, std::thread::hardware_concurrency()); }

/// The partitioning flags of `partition`, `compare` and `run` (strategy, phases, cost model).
void add_strategy_flags(CLI::App* cmd, partition::NamedOptions& n);
/// Registers a verb or a family (add_partition_verbs: partition, evaluate, compare, import,
/// calibrate; add_replay_verbs: replay, run; add_viz_verbs: viz, timeline, report).
using AddVerbs = void(CLI::App& app);
AddVerbs add_info, add_export, add_diff, add_capture, add_generate, add_demo, add_experiment,
    add_partition_verbs, add_replay_verbs, add_validate, add_viz_verbs, add_timeline, add_report,
    add_simulate, add_platform, add_explain;

/// Every verb, in the order `tgraph --help` lists them (main() and the command-line fuzz
/// target register the same set).
inline void add_all_verbs(CLI::App& app) {
  for (AddVerbs* add : {add_demo, add_experiment, add_capture, add_generate, add_info, add_export,
                        add_diff, add_partition_verbs, add_simulate, add_platform, add_replay_verbs,
                        add_validate, add_viz_verbs, add_explain})
    add(app);
}

}  // namespace tgraph::app
