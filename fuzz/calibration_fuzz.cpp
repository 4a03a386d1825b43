// SPDX-License-Identifier: MIT
// libFuzzer target: any text given as a calibration file gives a cost model with finite,
// non-negative constants, or a tgraph::Error.
#include <cmath>
#include <cstddef>
#include <cstdint>

#include "fuzz_util.hpp"
#include "tgraph/graph/error.hpp"
#include "tgraph/model/cost_model.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  try {
    const tgraph::model::CostModel m =
        tgraph::model::parse_calibration(tgraph::fuzz::as_text(data, size), "fuzz.json");
    if (!std::isfinite(m.sync_latency_ns) || m.sync_latency_ns < 0 ||
        !std::isfinite(m.per_byte_ns) || m.per_byte_ns < 0)
      tgraph::fuzz::invariant_failed();
  } catch (const tgraph::Error&) {
  }
  return 0;
}
