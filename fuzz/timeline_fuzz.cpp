// SPDX-License-Identifier: MIT
// libFuzzer target: any text given to `tgraph export R.json --format chrome` (a replay
// timeline) gives trace-event JSON or a tgraph::Error.
#include <cstddef>
#include <cstdint>

#include "fuzz_util.hpp"
#include "tgraph/graph/error.hpp"
#include "tgraph/replay/observer.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  try {
    const std::string out =
        tgraph::replay::chrome_from_timeline_json(tgraph::fuzz::as_text(data, size), "fuzz.json");
    if (out.empty()) tgraph::fuzz::invariant_failed();
  } catch (const tgraph::Error&) {
  }
  return 0;
}
