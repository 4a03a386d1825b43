// SPDX-License-Identifier: MIT
// `tgraph run`: a samples scene live, its partitioner and its report.
#include <optional>

#include "tgraph/measure/live.hpp"
#include "tgraph/measure/report.hpp"

namespace tgraph::measure {

SceneRunReport run_scene(const SceneRun& run) {
  std::optional<partition::StepPartitioner> part;
  if (run.method.policy == replay::Policy::kPartition)
    part = partition::step_partitioner(run.method.method, run.strategy.options());
  const int scene_steps = samples::make_scene(run.scene, run.scene_options)->default_steps();
  LiveOptions o = run.live;
  o.policy = run.method.policy;
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
