// SPDX-License-Identifier: MIT
// One entry for every experiment by name: the paper's four, metg and scaling.
#include <optional>

#include "common.hpp"
#include "tgraph/experiment/experiment.hpp"
#include "tgraph/experiment/metg.hpp"
#include "tgraph/experiment/scaling.hpp"
#include "tgraph/graph/error.hpp"

namespace tgraph::experiment {

NamedRun run_named(std::string_view name, const ExperimentOptions& o, Progress& progress) {
  if (!o.scenes.empty() && name != "scaling")
    throw OptionError("scenes", "applies to the scaling experiment only");
  if (const std::optional<ExperimentName> paper = parse_experiment_name(name)) {
    ExperimentOptions po = o;
    po.name = *paper;
    const ExperimentResult r = run_experiment(po, progress);
    return {experiment_text(r), experiment_json(r), r.failures()};
  }
  if (!o.subobjects.empty())
    throw OptionError("subobjects", "applies to the domain experiment only");
  if (name == "metg") {
    if (!o.calibration.empty())
      throw OptionError("calibration", "metg predicts nothing: it measures each policy");
    const MetgResult r = run_metg({o.quick, o.out, o.threads, o.methods, o.words}, progress);
    return {metg_text(r), metg_json(r), 0};
  }
  if (name == "scaling") {
    if (o.replay) throw OptionError("replay", "the scaling experiment makes live runs only");
    const ScalingResult r = run_scaling(
        {o.quick, o.out, o.threads, o.methods, o.steps, o.repeat, o.words, o.calibration, o.scenes},
        progress);
    return {scaling_text(r), scaling_json(r), r.failed.size()};
  }
  throw UsageError("unknown experiment '" + std::string(name) + "' (expected " +
                   detail::join(all_experiment_names(), ", ") + ")");
}

}  // namespace tgraph::experiment
