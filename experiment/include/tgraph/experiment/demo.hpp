// SPDX-License-Identifier: MIT
// `tgraph demo` (and `tgraph` alone): capture a built-in scene, partition it with every
// strategy, evaluate each offline, replay each on all cores against the work-stealing,
// barrier and StarPU baselines, and write the trace and the HTML report (viz/report.hpp).
#pragma once

#include <cstdint>
#include <functional>
#include <string>
#include <vector>

#include "tgraph/viz/report.hpp"

namespace tgraph::experiment {

/// What the demo runs.
struct DemoOptions {
  std::string scene = "bars64";         ///< built-in scene or scene file
  int steps = 10;                       ///< steps captured
  std::uint32_t threads = 1;            ///< replay threads (the command line: all hardware threads)
  std::uint32_t repeat = 3;             ///< timed passes per replay (medians)
  std::string out = "tgraph-demo";      ///< folder for the trace and report.html
};

/// What the demo measured.
struct DemoResult {
  std::string scene;
  int steps = 0;
  std::uint32_t threads = 1;
  std::uint32_t repeat = 1;
  std::uint64_t tasks = 0;  ///< tasks of the first step
  double parallelism = 0;   ///< work / span of the first step
  std::string trace_path;
  std::string report_path;
  /// The cost model of the predictions: "defaults" (CostModel::defaults(), no calibration
  /// file) or the path of the calibration file read.
  std::string cost_model;
  /// One row per strategy at `threads`, then the baselines (predictions at smaller K are in
  /// the report only).
  std::vector<viz::MethodRow> rows;
};

/// Runs the demo and writes `<out>/<scene>.tgt` and `<out>/report.html`; `say` (optional)
/// receives progress lines. Bad options: tgraph::OptionError; a capture that
/// misused the API: std::runtime_error.
///
///   DemoResult r = run_demo({.scene = "bars64", .threads = 2}, [](const std::string& s) {
///     std::fprintf(stderr, "%s\n", s.c_str());
///   });
DemoResult run_demo(const DemoOptions& options,
                    const std::function<void(const std::string&)>& say = {});

/// The demo as one JSON object (scene, steps, threads, trace, report, cost_model,
/// rows).
std::string demo_json(const DemoResult& result);
/// `tgraph demo`'s table, as printed on stdout: the cost model of its predictions, then the
/// trace's and the report's absolute paths.
std::string demo_text(const DemoResult& result);

}  // namespace tgraph::experiment
