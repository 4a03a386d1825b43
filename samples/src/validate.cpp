// SPDX-License-Identifier: MIT
// `tgraph validate`'s pipeline: live run, capture + replay, simulation.
#include "tgraph/samples/validate.hpp"

#include <cstdio>
#include <vector>
#include <nlohmann/json.hpp>

#include "tgraph/capture/recorder.hpp"
#include "tgraph/graph/error.hpp"
#include "tgraph/graph/median.hpp"
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
  const auto model = partition::select_cost_model("calibrated", "");

  for (std::uint32_t round = 0; round < o.repeat; ++round) {
    ValidationRound r;
    // 1. The live run (the truth), timed against the uninstrumented engine.
    replay::LiveOptions lo;
    lo.policy = v.choice.policy;
    lo.exec.threads = v.threads;
    lo.steps = o.steps;
    lo.repeat = 1;
    lo.observe = false;
    const std::string scene = o.scene;
    const replay::LiveResult live = replay::run_live(
        [scene] { return make_live_engine(scene); }, part ? &*part : nullptr, lo);
    r.live_ns = live.wall_ns;
    r.engine_ns = live.baseline_wall_ns;

    // 2. A capture of the same steps, replayed with synthetic bodies under the same policy.
    auto sc = make_scene(o.scene);
    capture::Recorder rec(capture::Mode::kCapture);
    Trace trace;
    trace.header = scene_header(*sc, 1);
    for (std::uint32_t s = 0; s < o.steps; ++s) {
      sc->step(rec);
      trace.steps.push_back(rec.end_step());
      r.host_ns += trace.steps.back().host_ns;
    }
    std::optional<TraceAssignment> assignment;
    if (partition)
      assignment = partition::partition_trace(trace, v.choice.method, v.threads).assignment;
    replay::ReplayOptions ro;
    ro.policy = v.choice.policy;
    ro.exec.threads = v.threads;
    ro.repeat = 1;
    ro.observe = false;
    ro.sequential_baseline = false;
    r.replay_ns = replay::replay_trace(trace, assignment ? &*assignment : nullptr, ro).wall_ns;

    // 3. The simulator's makespan of the same partition (partition policy only).
    if (assignment)
      for (std::uint64_t ns : partition::predicted_makespans(trace, *assignment, model))
        r.predicted_ns += ns;
    v.rounds.push_back(r);
  }

  std::vector<double> live, engine, rep, pred, rl, pl, pr;
  for (const ValidationRound& r : v.rounds) {
    const double l = static_cast<double>(r.live_ns), x = static_cast<double>(r.replay_ns),
                 p = static_cast<double>(r.predicted_ns);
    live.push_back(l);
    engine.push_back(static_cast<double>(r.engine_ns));
    rep.push_back(x);
    pred.push_back(p);
    rl.push_back(x / l);
    pl.push_back(p / l);
    pr.push_back(p / x);
  }
  v.live_ns = static_cast<std::int64_t>(median(live));
  v.engine_ns = static_cast<std::int64_t>(median(engine));
  v.replay_ns = static_cast<std::int64_t>(median(rep));
  v.predicted_ns = partition ? static_cast<std::uint64_t>(median(pred)) : 0;
  v.replay_over_live = median(rl);
  if (partition) {
    v.predicted_over_live = median(pl);
    v.predicted_over_replay = median(pr);
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
  const bool pred = v.predicted_ns != 0;
  nlohmann::json rounds = nlohmann::json::array();
  for (const ValidationRound& r : v.rounds)
    rounds.push_back({{"live_wall_ns", r.live_ns},
                      {"engine_wall_ns", r.engine_ns},
                      {"replay_wall_ns", r.replay_ns},
                      {"predicted_ns", pred ? nlohmann::json(r.predicted_ns) : nlohmann::json(nullptr)},
                      {"host_ns", r.host_ns}});
  nlohmann::json j = {{"scene", o.scene},
                      {"policy", std::string(to_string(v.choice.policy))},
                      {"method", method_name(v)},
                      {"threads", v.threads},
                      {"steps", o.steps},
                      {"rounds", rounds},
                      {"live_wall_ns", v.live_ns},
                      {"engine_wall_ns", v.engine_ns},
                      {"live_speedup", v.live_ns > 0 ? static_cast<double>(v.engine_ns) /
                                                           static_cast<double>(v.live_ns)
                                                     : 0.0},
                      {"replay_wall_ns", v.replay_ns},
                      {"replay_over_live", v.replay_over_live}};
  j["predicted_ns"] = pred ? nlohmann::json(v.predicted_ns) : nlohmann::json(nullptr);
  j["predicted_over_live"] = pred ? nlohmann::json(v.predicted_over_live) : nlohmann::json(nullptr);
  j["predicted_over_replay"] =
      pred ? nlohmann::json(v.predicted_over_replay) : nlohmann::json(nullptr);
  return j.dump() + "\n";
}

std::string validation_text(const Validation& v, const ValidateOptions& o) {
  char line[512];
  std::string out;
  std::snprintf(line, sizeof line,
                "validate %s, %s (%s), %u threads, %u steps (medians of %zu rounds; ratios: "
                "medians of each round's)\n",
                o.scene.c_str(), std::string(to_string(v.choice.policy)).c_str(),
                method_name(v).c_str(), v.threads, o.steps, v.rounds.size());
  out += line;
  std::snprintf(line, sizeof line,
                "  live run        %10.3f ms   (uninstrumented engine %.3f ms, speed-up %.2f)\n",
                static_cast<double>(v.live_ns) / 1e6, static_cast<double>(v.engine_ns) / 1e6,
                v.live_ns > 0 ? static_cast<double>(v.engine_ns) / static_cast<double>(v.live_ns)
                              : 0.0);
  out += line;
  std::snprintf(line, sizeof line, "  replay          %10.3f ms   replay / live %.3f\n",
                static_cast<double>(v.replay_ns) / 1e6, v.replay_over_live);
  out += line;
  if (v.predicted_ns != 0) {
    std::snprintf(line, sizeof line,
                  "  simulator       %10.3f ms   simulator / live %.3f, simulator / replay %.3f\n",
                  static_cast<double>(v.predicted_ns) / 1e6, v.predicted_over_live,
                  v.predicted_over_replay);
    out += line;
  }
  return out;
}

}  // namespace tgraph::samples
