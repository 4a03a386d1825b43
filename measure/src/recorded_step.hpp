// SPDX-License-Identifier: MIT
// What the two live engines (the samples scene, an outside engine's callbacks) share: a step
// recorded in deferred mode handed over as a LiveStep, and the recorded data as the state.
#pragma once

#include <string>
#include <vector>

#include "tgraph/capture/recorder.hpp"
#include "tgraph/measure/engine.hpp"

namespace tgraph::measure::detail {

/// Ends the step `rec` records and hands over its program; UsageError naming `engine` when
/// the recorder counted API misuses.
LiveStep take_recorded_step(capture::Recorder& rec, const std::string& engine);

/// Every datum of `rec` with storage, as a region of the state to compare.
std::vector<StateRegion> recorded_state(const capture::Recorder& rec);

}  // namespace tgraph::measure::detail
