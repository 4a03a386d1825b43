// SPDX-License-Identifier: MIT
// The partition executor's own time per task, which only this module (it runs the executor)
// can measure, for the model's calibration (tgraph::model::calibrate_machine).
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "tgraph/model/cost_model.hpp"

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

/// executor_overhead_samples with the default options and `samples` samples: the sampler
/// model::calibrate_machine takes.
model::ExecutorOverheadSampler executor_overhead_sampler();

/// model::calibrate_machine(options) with this module's executor_overhead_sampler.
model::Calibration calibrate_machine(const model::CalibrateOptions& options = {});

/// `tgraph calibrate`: model::calibrate_file with this module's executor_overhead_sampler.
std::string calibrate_file(const model::CalibrateOptions& options, const std::string& path,
                           bool json);

}  // namespace tgraph::measure
