// SPDX-License-Identifier: MIT
// The cost model of the simulator tests: link costs only.
#pragma once

#include "tgraph/model/cost_model.hpp"

namespace tgraph::model::testing {

/// A cost model with only these link costs (no reduction, inflation or overheads).
inline CostModel link_model(double latency, double per_byte = 0) {
  CostModel m;
  m.sync_latency_ns = latency;
  m.per_byte_ns = per_byte;
  m.source = "test";
  return m;
}

}  // namespace tgraph::model::testing
