// SPDX-License-Identifier: MIT
// A method choice as a live run takes it; `tgraph run`: a samples scene live, its partitioner
// and its report.
#include <memory>
#include <optional>
#include <utility>
#include <vector>

#include "tgraph/measure/live.hpp"
#include "tgraph/measure/report.hpp"

namespace tgraph::measure {

std::optional<partition::StepPartitioner> live_partitioner(
    const MethodChoice& choice, const partition::Options& strategy, LiveOptions& options,
    std::shared_ptr<std::vector<partition::Stats>> calls) {
  options.policy = choice.policy;
  if (choice.policy != replay::Policy::kPartition) return std::nullopt;
  return partition::step_partitioner(choice.method, strategy, std::move(calls));
}

SceneRunReport run_scene(const SceneRun& run) {
  LiveOptions o = run.live;
  const std::optional<partition::StepPartitioner> part =
      live_partitioner(run.method, run.strategy.options(), o);
  const int scene_steps = samples::make_scene(run.scene, run.scene_options)->default_steps();
  o.loop_share = run.strategy.values.loop_share;
  o.steps = run.steps.value_or(static_cast<std::uint32_t>(scene_steps));
  const std::string scene = run.scene, method = method_name(run.method);
  const samples::SceneOptions scene_options = run.scene_options;
  SceneRunReport r;
  r.result = run_live([scene, scene_options] { return make_live_engine(scene, scene_options); },
                      part ? &*part : nullptr, o);
  r.report = run.json ? to_json(r.result, scene, method) + "\n"
                      : to_text(r.result, scene, method, o.repeat);
  return r;
}

}  // namespace tgraph::measure
