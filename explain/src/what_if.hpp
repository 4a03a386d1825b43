// SPDX-License-Identifier: MIT
// Virtual speed-ups (Coz, SOSP'15) of a step: through the built-in simulator or on its
// executed schedule.
#pragma once

#include <vector>

#include "step_view.hpp"
#include "tgraph/explain/explain.hpp"

namespace tgraph::explain::detail {

/// The step's predicted time under each change (each task kind, and each of the 8 objects
/// with the most work, 10 % and 50 % faster; each cause free): the observed makespan x
/// model(changed) / model(unchanged), the model the built-in simulator on the step's
/// executed graph and assignment, or the executed schedule re-run (every thread's order,
/// the time between its bodies and each hand-off's latency as measured) for the causes
/// the simulator has no parameter for and for steps it cannot run (WhatIf::model says
/// which; docs/explain.md); the largest gain first. The simulator is used when its makespan
/// of the step unchanged is within `fit` of the observed (ExplainOptions::simulator_fit);
/// `simulated_ns` (when not null) gets that makespan (0: not simulated).
std::vector<WhatIf> what_ifs(const StepView& v, const StepExplanation& s, double fit = 0.25,
                             std::int64_t* simulated_ns = nullptr);

/// The makespan (serial phases + execution) of the step re-run with bodies of kind `kind`
/// `fraction` shorter (0.5: half as long); the executed schedule otherwise as measured.
std::int64_t predict_kind_faster(const StepView& v, std::int64_t serial_ns, KindId kind,
                                 double fraction);

}  // namespace tgraph::explain::detail
