// SPDX-License-Identifier: MIT
// The verbs of the `tgraph` command line. Each verb lives in its own cmd_<verb>.cpp and
// only parses flags and calls the modules.
#pragma once

#include <CLI/CLI.hpp>
#include <cstdint>
#include <nlohmann/json.hpp>
#include <optional>
#include <stdexcept>
#include <string>
#include <vector>

#include "tgraph/graph/error.hpp"
#include "tgraph/graph/file_util.hpp"
#include "tgraph/graph/trace.hpp"
#include "tgraph/graph/trace_io.hpp"
#include "tgraph/samples/capture_run.hpp"

namespace tgraph::app {

/// The work itself failed (exit 1), as opposed to bad input (tgraph::Error, exit 2).
class Failure : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

/// Values of a verb's flags that no module's option struct holds (each verb owns one; module
/// options such as partition::NamedOptions or replay::LiveOptions hold the rest).
struct Args {
  std::string input, second, output, method, policy, format, cw, timeline, chrome, csv;
  std::vector<std::string> names;
  std::vector<std::uint32_t> counts;
  std::vector<double> values;
  std::optional<int> steps;
  std::uint32_t k = 0;
  std::uint64_t unit_ns = 1000, edge_bytes = 8;
  bool json = false, recover = false, no_pin = false, no_touch = false, no_baseline = false;
  bool no_observe = false, no_reuse = false, no_elide_waits = false;
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
/// "<cpu model>, N hardware threads", for trace headers (libgraph).
using tgraph::machine_description;
/// Threads a verb uses by default: all hardware threads (at least 1).
std::uint32_t default_threads();
/// Header of a trace captured from a scene (samples).
using samples::scene_header;

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
