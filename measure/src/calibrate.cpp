// SPDX-License-Identifier: MIT
// The partition executor's own time per task, for the model's calibration of the machine.
#include "tgraph/measure/calibrate.hpp"

#include <algorithm>
#include <string>
#include <vector>

#include "tgraph/graph/error.hpp"
#include "tgraph/graph/generate.hpp"
#include "tgraph/measure/replay_trace.hpp"

namespace tgraph::measure {

std::vector<double> executor_overhead_samples(std::uint32_t threads,
                                              const ExecutorOverheadOptions& options) {
  if (threads < 2) throw OptionError("threads", "must be at least 2");
  if (options.tasks_per_thread == 0 || options.samples == 0 || options.repeat == 0)
    throw OptionError("tasks_per_thread", "tasks, samples and passes must be at least 1");
  // Round robin, as a step's tasks of many objects interleave: thread p runs every
  // threads-th task, each after the previous one of its chain (an edge on its own thread).
  const ChainsStep chains = chains_step(threads, options.tasks_per_thread, options.cost_ns);
  // Step 0 warms up (threads started, buffers first touched); each later step is a sample.
  Trace trace;
  trace.header.scene = "executor overhead";
  TraceAssignment as{"round robin", threads, {}, {}};
  for (std::uint32_t s = 0; s <= options.samples; ++s) {
    trace.steps.push_back(chains.graph);
    as.steps.push_back(chains.assignment);
  }
  ReplayOptions ro;
  ro.policy = replay::Policy::kPartition;
  ro.exec.threads = threads;
  ro.repeat = options.repeat;
  ro.observe = false;
  ro.sequential_baseline = true;
  const ReplayResult r = replay_trace(trace, &as, ro);
  std::vector<double> out;
  for (std::size_t s = 1; s < r.steps.size(); ++s) {
    const StepMeasure& m = r.steps[s];
    out.push_back((static_cast<double>(m.run_ns) -
                   static_cast<double>(m.sequential_wall_ns) / threads) /
                  options.tasks_per_thread);
  }
  return out;
}

model::ExecutorOverheadSampler executor_overhead_sampler() {
  return [](std::uint32_t threads, std::uint32_t samples) {
    ExecutorOverheadOptions eo;
    eo.samples = samples;
    return executor_overhead_samples(threads, eo);
  };
}

model::Calibration calibrate_machine(const model::CalibrateOptions& options) {
  return model::calibrate_machine(options, executor_overhead_sampler());
}

std::string calibrate_file(const model::CalibrateOptions& options, const std::string& path,
                           bool json) {
  return model::calibrate_file(options, path, json, executor_overhead_sampler());
}

}  // namespace tgraph::measure
