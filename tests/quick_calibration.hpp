// SPDX-License-Identifier: MIT
// The smallest calibration the tests run for real: every measurement taken, few rounds.
#pragma once

#include "tgraph/model/cost_model.hpp"

namespace tgraph::testing {

/// 3 samples of 500 spinning and 20 parked hand-offs, 1 inflation round over 64 KiB, 100
/// reductions and 20 ms of looking for interruptions: well under a second on 2 cores.
inline model::CalibrateOptions quick_calibration() {
  model::CalibrateOptions o;
  o.rounds = 500;
  o.park_rounds = 20;
  o.inflation_rounds = 1;
  o.inflation_bytes = 1 << 16;
  o.reduction_rounds = 100;
  o.interruption_ms = 20;
  o.samples = 3;
  return o;
}

}  // namespace tgraph::testing
