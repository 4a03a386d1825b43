// SPDX-License-Identifier: MIT
// The partition executor's own time per task, beside partition's measurements of the machine.
#include "tgraph/measure/calibrate.hpp"

#include <algorithm>
#include <chrono>
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

partition::Calibration calibrate_machine(const partition::CalibrateOptions& options) {
  partition::Calibration c = partition::measure_calibration(options);
  const auto start = std::chrono::steady_clock::now();
  ExecutorOverheadOptions eo;
  eo.samples = static_cast<std::uint32_t>(std::max(c.samples, 1));
  // The same K as the inflation's (its curve lists 1 first).
  for (const partition::ThreadsPoint& p : c.inflation) {
    if (p.threads < 2) continue;
    const partition::Spread s = partition::spread_of(executor_overhead_samples(p.threads, eo));
    c.executor_overhead_spread.push_back({p.threads, s});
    // Below 0 is the noise of a machine on which the executor costs nothing measurable.
    c.executor_overhead.push_back({p.threads, std::max(0.0, s.median)});
  }
  c.seconds += std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  return c;
}

std::string calibrate_file(const partition::CalibrateOptions& options, const std::string& path,
                           bool json) {
  const partition::Calibration c = calibrate_machine(options);  // runtime_error: the work's
  return partition::calibration_report(c, partition::save_calibration(c, path), json);
}

}  // namespace tgraph::measure
