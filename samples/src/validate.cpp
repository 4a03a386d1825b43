// SPDX-License-Identifier: MIT
// `tgraph validate`'s pipeline: live run, capture + replay, simulation.
#include "tgraph/samples/validate.hpp"

#include <cstdio>
#include <nlohmann/json.hpp>

#include "tgraph/capture/recorder.hpp"
#include "tgraph/graph/error.hpp"
#include "tgraph/partition/cost_model.hpp"
#include "tgraph/partition/simulator.hpp"
#include "tgraph/partition/strategy.hpp"
#include "tgraph/samples/capture_run.hpp"
#include "tgraph/samples/live_engine.hpp"

namespace tgraph::samples {

Validation validate_scene(const ValidateOptions& o) {
  Validation v;
  v.choice = replay::choose_method(o.method);
  const bool partition = v.choice.policy == replay::Policy::kPartition;
  std::optional<partition::StepPartitioner> part;
  if (partition) part = partition::step_partitioner(v.choice.method);
  v.threads = v.choice.policy == replay::Policy::kSequential ? 1 : o.threads;
  if (v.threads == 0 || o.steps == 0 || o.repeat == 0)
    throw UsageError("--threads, --steps and --repeat must be at least 1");

  // 1. The live run (the truth), timed against the uninstrumented engine.
  replay::LiveOptions lo;
  lo.policy = v.choice.policy;
  lo.exec.threads = v.threads;
  lo.steps = o.steps;
  lo.repeat = o.repeat;
  lo.observe = false;
  const std::string scene = o.scene;
  v.live =
      replay::run_live([scene] { return make_live_engine(scene); }, part ? &*part : nullptr, lo);

  // 2. A capture of the same steps, replayed with synthetic bodies under the same policy.
  auto sc = make_scene(o.scene);
  capture::Recorder rec(capture::Mode::kCapture);
  Trace trace;
  trace.header = scene_header(*sc, 1);
  for (std::uint32_t s = 0; s < o.steps; ++s) {
    sc->step(rec);
    trace.steps.push_back(rec.end_step());
  }
  std::optional<TraceAssignment> assignment;
  if (partition)
    assignment = partition::partition_trace(trace, v.choice.method, v.threads).assignment;
  replay::ReplayOptions ro;
  ro.policy = v.choice.policy;
  ro.exec.threads = v.threads;
  ro.repeat = o.repeat;
  ro.observe = false;
  v.replay = replay::replay_trace(trace, assignment ? &*assignment : nullptr, ro);

  // 3. The simulator's makespan of the same partition (partition policy only).
  if (assignment) {
    const auto model = partition::select_cost_model("calibrated", "");
    for (std::uint64_t ns : partition::predicted_makespans(trace, *assignment, model))
      v.predicted_ns += ns;
  }
  return v;
}

namespace {
std::string method_name(const Validation& v) {
  return v.choice.policy == replay::Policy::kPartition ? v.choice.method
                                                       : std::string(to_string(v.choice.policy));
}
}  // namespace

std::string validation_json(const Validation& v, const ValidateOptions& o) {
  const double l = static_cast<double>(v.live.wall_ns), r = static_cast<double>(v.replay.wall_ns),
               p = static_cast<double>(v.predicted_ns);
  const bool pred = v.predicted_ns != 0;
  nlohmann::json j = {{"scene", o.scene},
                      {"policy", std::string(to_string(v.choice.policy))},
                      {"method", method_name(v)},
                      {"threads", v.threads},
                      {"steps", o.steps},
                      {"live_wall_ns", v.live.wall_ns},
                      {"engine_wall_ns", v.live.baseline_wall_ns},
                      {"live_speedup", v.live.speedup},
                      {"replay_wall_ns", v.replay.wall_ns},
                      {"replay_over_live", r / l}};
  j["predicted_ns"] = pred ? nlohmann::json(v.predicted_ns) : nlohmann::json(nullptr);
  j["predicted_over_live"] = pred ? nlohmann::json(p / l) : nlohmann::json(nullptr);
  j["predicted_over_replay"] = pred ? nlohmann::json(p / r) : nlohmann::json(nullptr);
  return j.dump() + "\n";
}

std::string validation_text(const Validation& v, const ValidateOptions& o) {
  const double l = static_cast<double>(v.live.wall_ns), r = static_cast<double>(v.replay.wall_ns),
               p = static_cast<double>(v.predicted_ns);
  char line[512];
  std::string out;
  std::snprintf(line, sizeof line, "validate %s, %s (%s), %u threads, %u steps (medians of %u)\n",
                o.scene.c_str(), std::string(to_string(v.choice.policy)).c_str(),
                method_name(v).c_str(), v.threads, o.steps, o.repeat);
  out += line;
  std::snprintf(line, sizeof line,
                "  live run        %10.3f ms   (uninstrumented engine %.3f ms, speed-up %.2f)\n",
                l / 1e6, static_cast<double>(v.live.baseline_wall_ns) / 1e6, v.live.speedup);
  out += line;
  std::snprintf(line, sizeof line, "  replay          %10.3f ms   replay / live %.3f\n", r / 1e6,
                r / l);
  out += line;
  if (v.predicted_ns != 0) {
    std::snprintf(line, sizeof line,
                  "  simulator       %10.3f ms   simulator / live %.3f, simulator / replay %.3f\n",
                  p / 1e6, p / l, p / r);
    out += line;
  }
  return out;
}

}  // namespace tgraph::samples
