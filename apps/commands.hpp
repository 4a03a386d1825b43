// SPDX-License-Identifier: MIT
// The verbs of the `tgraph` command line. Each verb lives in its own cmd_<verb>.cpp and
// only parses flags and calls the modules.
#pragma once

#include <CLI/CLI.hpp>
#include <nlohmann/json.hpp>
#include <stdexcept>
#include <string>

#include "tgraph/graph/error.hpp"
#include "tgraph/graph/file_util.hpp"
#include "tgraph/graph/trace.hpp"
#include "tgraph/graph/trace_io.hpp"

namespace tgraph::samples {
class Scene;
}

namespace tgraph::app {

/// The work itself failed (exit 1), as opposed to bad input (tgraph::Error, exit 2).
class Failure : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

/// Prints a JSON object on stdout (one line, as `--json` promises).
void print_json(const nlohmann::json& j);
/// Reads a trace for a verb; malformed input throws InputError (exit 2).
Trace load_trace(const std::string& path, bool recover = false);
/// A whole file as text (InputError when it cannot be read).
inline std::string read_file_text(const std::string& path) {
  const std::vector<std::uint8_t> bytes = read_file_bytes(path);
  return std::string(bytes.begin(), bytes.end());
}
/// "<cpu model>, N hardware threads", for trace headers.
std::string machine_description();
/// Threads a verb uses by default: all hardware threads (at least 1).
std::uint32_t default_threads();
/// Header of a trace captured from `scene` (engine, integrator, dt, seed, machine).
TraceHeader scene_header(const samples::Scene& scene, std::uint64_t seed);

// Registration of each verb (one function per cmd_*.cpp).
void add_info(CLI::App& app);
void add_export(CLI::App& app);
void add_diff(CLI::App& app);
void add_capture(CLI::App& app);
void add_demo(CLI::App& app);
void add_partition_verbs(CLI::App& app);  // partition, evaluate, compare, import, calibrate
void add_replay_verbs(CLI::App& app);     // replay, run
void add_validate(CLI::App& app);         // validate (live vs replay vs simulator)
void add_viz_verbs(CLI::App& app);        // viz, then add_timeline and add_report
void add_timeline(CLI::App& app);
void add_report(CLI::App& app);

}  // namespace tgraph::app
