// SPDX-License-Identifier: MIT
// `tgraph validate`: the live run of a scene (the truth), the synthetic replay of a capture of
// the same steps and the simulator's prediction of the same partition, side by side.
#pragma once

#include <cstdint>
#include <string>

#include "tgraph/replay/live.hpp"
#include "tgraph/replay/measure.hpp"

namespace tgraph::samples {

/// What to validate (the flags of `tgraph validate`).
struct ValidateOptions {
  std::string scene;
  std::string method = "owner";  ///< strategy, or a baseline policy (worksteal, barrier...)
  std::uint32_t threads = 1;
  std::uint32_t steps = 20;
  std::uint32_t repeat = 3;  ///< timed passes of each (medians)
};

/// The three figures of one validation.
struct Validation {
  replay::MethodChoice choice;
  std::uint32_t threads = 1;
  replay::LiveResult live;
  replay::ReplayResult replay;
  std::uint64_t predicted_ns = 0;  ///< simulator, partition policy only (0: none)
};

/// Runs the live run, captures the same steps and replays them under the same policy, and
/// simulates the partition. UsageError for zero threads, steps or passes, or an unknown method.
Validation validate_scene(const ValidateOptions& options);

/// `tgraph validate --json` (ratios replay / live, predicted / live, predicted / replay).
std::string validation_json(const Validation& v, const ValidateOptions& options);
/// `tgraph validate`'s text.
std::string validation_text(const Validation& v, const ValidateOptions& options);

}  // namespace tgraph::samples
