// SPDX-License-Identifier: MIT
// libFuzzer target: any text given as a replay timeline (`tgraph export R.json --format
// chrome`, `tgraph replay --chrome`, `tgraph timeline R.json`, `tgraph report --replay
// R.json`) or as a comparison (`tgraph report --compare C.json`) gives its output or a
// tgraph::Error.
#include <cstddef>
#include <cstdint>
#include <string>

#include "fuzz_util.hpp"
#include "tgraph/graph/error.hpp"
#include "tgraph/viz/report.hpp"
#include "tgraph/viz/timeline.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::string_view text = tgraph::fuzz::as_text(data, size);
  namespace viz = tgraph::viz;
  try {
    const tgraph::Timeline t = tgraph::parse_timeline(text, "fuzz.json");
    // What the pictures compute from it: steps end to end, flows, the Gantt chart.
    const std::vector<std::int64_t> offsets = t.step_offsets();
    for (const tgraph::TimelineTask& e : t.tasks)
      if (e.step >= offsets.size() || e.thread >= t.threads) tgraph::fuzz::invariant_failed();
    if (viz::chrome_trace(t).empty()) tgraph::fuzz::invariant_failed();
    if (viz::render_timeline(t, viz::TimelineFormat::kSvg, "fuzz").empty())
      tgraph::fuzz::invariant_failed();
  } catch (const tgraph::Error&) {
  }
  viz::ReportContent c;
  try {
    viz::add_replay_json(c, text, "fuzz.json");
  } catch (const tgraph::Error&) {
  }
  try {
    viz::add_compare_json(c, text, "fuzz.json");
  } catch (const tgraph::Error&) {
  }
  return 0;
}
