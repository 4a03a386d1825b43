// SPDX-License-Identifier: MIT
// libFuzzer target: any text given to the STG reader gives a one-step trace or a
// tgraph::Error; a graph that parses is a valid step.
#include <cstddef>
#include <cstdint>

#include "fuzz_util.hpp"
#include "tgraph/graph/error.hpp"
#include "tgraph/graph/stg.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  try {
    const tgraph::StgGraph g =
        tgraph::parse_stg(tgraph::fuzz::as_text(data, size), "fuzz.stg");
    if (g.trace.steps.size() != 1 || !g.trace.steps[0].validate().empty())
      tgraph::fuzz::invariant_failed();
  } catch (const tgraph::Error&) {
  }
  return 0;
}
