// SPDX-License-Identifier: MIT
// `tgraph calibrate`: partition's measurements of the machine, and the partition executor's
// own time per task, which only this module (it runs the executor) can measure.
#pragma once

#include <cstdint>
#include <string>

#include "tgraph/partition/cost_model.hpp"

namespace tgraph::measure {

/// How the executor's time per task is measured.
struct ExecutorOverheadOptions {
  std::uint32_t tasks_per_thread = 4000;  ///< per step and thread
  std::uint64_t cost_ns = 1000;           ///< each task's recorded cost (a synthetic body)
  std::uint32_t samples = 15;             ///< steps measured (each one sample), after a warm-up
  std::uint32_t repeat = 3;               ///< passes of each (the median pass kept per step)
};

/// One sample per step of the partition executor's own time per task instance at `threads`
/// threads (ns): a step of `threads` independent chains of tasks, one per thread, each task
/// rewriting its chain's datum, run on `threads` threads, against the same step run by the
/// sequential executor in the same passes (interleaved): (its run - the sequential run /
/// threads) / tasks per thread. What the partition executor adds to each task (its
/// program walk, the claim of a task that a thief could take, the publications of its
/// completion, the end of the step) beyond calling the body. Throws OptionError for
/// threads < 2 or an empty step.
std::vector<double> executor_overhead_samples(std::uint32_t threads,
                                              const ExecutorOverheadOptions& options = {});

/// partition::measure_calibration(options), with the executor's time per task at the same
/// K (2, 4, ..., the CPUs this process may use; `options.samples` samples each; the median
/// kept, at least 0) in `executor_overhead`.
partition::Calibration calibrate_machine(const partition::CalibrateOptions& options = {});

/// calibrate_machine(options), saved to `path` (partition::save_calibration): its report.
std::string calibrate_file(const partition::CalibrateOptions& options, const std::string& path,
                           bool json);

}  // namespace tgraph::measure
