// SPDX-License-Identifier: MIT
// `tgraph validate`: the live run, the synthetic replay of a capture of the same scene and
// the simulator's prediction, side by side with their ratios (the live run is the truth).
#include <cstdio>
#include <memory>

#include "commands.hpp"
#include "tgraph/capture/recorder.hpp"
#include "tgraph/partition/cost_model.hpp"
#include "tgraph/partition/simulator.hpp"
#include "tgraph/partition/strategy.hpp"
#include "tgraph/replay/live.hpp"
#include "tgraph/replay/measure.hpp"
#include "tgraph/samples/live_engine.hpp"
#include "tgraph/samples/scene.hpp"

namespace tgraph::app {
namespace {

namespace tp = tgraph::partition;
namespace tr = tgraph::replay;

struct ValidateCmd {
  std::string scene, method = "owner";
  std::uint32_t threads = default_threads();
  std::uint32_t steps = 20, repeat = 3;
  bool json = false;
};

void run_validate(const ValidateCmd& c) {
  tr::Policy policy = tr::Policy::kPartition;
  if (const auto p = tr::parse_policy(c.method); p && *p != tr::Policy::kPartition) policy = *p;
  const bool partition = policy == tr::Policy::kPartition;
  std::shared_ptr<tp::Strategy> strategy = partition ? tp::make_strategy(c.method) : nullptr;
  const std::uint32_t k = policy == tr::Policy::kSequential ? 1 : c.threads;
  if (k == 0 || c.steps == 0 || c.repeat == 0)
    throw UsageError("--threads, --steps and --repeat must be at least 1");

  // 1. The live run (the truth), timed against the uninstrumented engine.
  tr::LiveOptions lo;
  lo.policy = policy;
  lo.exec.threads = k;
  lo.steps = c.steps;
  lo.repeat = c.repeat;
  lo.observe = false;
  const std::string scene = c.scene;
  const tr::LivePartitioner part = [strategy](const StepGraph& g, std::uint32_t kk,
                                              const StepGraph* pg, const Assignment* pa) {
    return strategy->partition(g, kk, tp::Previous{pg, pa}, tp::Options{}).assignment;
  };
  const tr::LiveResult live = tr::run_live(
      [scene] { return samples::make_live_engine(scene); }, partition ? &part : nullptr, lo);

  // 2. A capture of the same steps, replayed with synthetic bodies under the same policy.
  auto sc = samples::make_scene(c.scene);
  capture::Recorder rec(capture::Mode::kCapture);
  Trace trace;
  trace.header = scene_header(*sc, 1);
  for (std::uint32_t s = 0; s < c.steps; ++s) {
    sc->step(rec);
    trace.steps.push_back(rec.end_step());
  }
  std::optional<TraceAssignment> assignment;
  if (partition) assignment = tp::partition_trace(trace, c.method, k).assignment;
  tr::ReplayOptions ro;
  ro.policy = policy;
  ro.exec.threads = k;
  ro.repeat = c.repeat;
  ro.observe = false;
  const tr::ReplayResult replay = tr::replay_trace(trace, assignment ? &*assignment : nullptr, ro);

  // 3. The simulator's makespan of the same partition (partition policy only).
  std::uint64_t predicted = 0;
  if (assignment) {
    const tp::CostModel model = tp::select_cost_model("calibrated", "");
    for (std::size_t s = 0; s < trace.steps.size(); ++s)
      predicted += tp::simulate(trace.steps[s], assignment->steps[s], model).makespan_ns;
  }
  const double l = static_cast<double>(live.wall_ns), r = static_cast<double>(replay.wall_ns),
               p = static_cast<double>(predicted);
  nlohmann::json j = {{"scene", c.scene},
                      {"policy", std::string(tr::to_string(policy))},
                      {"method", partition ? c.method : std::string(tr::to_string(policy))},
                      {"threads", k},
                      {"steps", c.steps},
                      {"live_wall_ns", live.wall_ns},
                      {"engine_wall_ns", live.baseline_wall_ns},
                      {"live_speedup", live.speedup},
                      {"replay_wall_ns", replay.wall_ns},
                      {"replay_over_live", r / l}};
  j["predicted_ns"] = predicted ? nlohmann::json(predicted) : nlohmann::json(nullptr);
  j["predicted_over_live"] = predicted ? nlohmann::json(p / l) : nlohmann::json(nullptr);
  j["predicted_over_replay"] = predicted ? nlohmann::json(p / r) : nlohmann::json(nullptr);
  if (c.json) {
    print_json(j);
    return;
  }
  std::printf("validate %s, %s (%s), %u threads, %u steps (medians of %u)\n", c.scene.c_str(),
              std::string(tr::to_string(policy)).c_str(), j["method"].get<std::string>().c_str(),
              k, c.steps, c.repeat);
  std::printf("  live run        %10.3f ms   (uninstrumented engine %.3f ms, speed-up %.2f)\n",
              l / 1e6, static_cast<double>(live.baseline_wall_ns) / 1e6, live.speedup);
  std::printf("  replay          %10.3f ms   replay / live %.3f\n", r / 1e6, r / l);
  if (predicted)
    std::printf("  simulator       %10.3f ms   simulator / live %.3f, simulator / replay %.3f\n",
                p / 1e6, p / l, p / r);
}

}  // namespace

void add_validate(CLI::App& app) {
  auto c = std::make_shared<ValidateCmd>();
  auto* cmd = app.add_subcommand(
      "validate", "Live run, replay of a capture and simulator side by side, with their ratios");
  cmd->add_option("--scene", c->scene, "Built-in scene or scene file")->required();
  cmd->add_option("--threads,-k", c->threads, "Threads");
  cmd->add_option("--method", c->method,
                  "Partitioning strategy, or a baseline policy (worksteal, barrier, sequential)");
  cmd->add_option("--steps", c->steps, "Steps (default 20)");
  cmd->add_option("--repeat", c->repeat, "Timed passes of each (medians; default 3)");
  cmd->add_flag("--json", c->json, "Print one JSON object");
  cmd->callback([c] { run_validate(*c); });
}

}  // namespace tgraph::app
