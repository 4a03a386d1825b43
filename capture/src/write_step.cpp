// SPDX-License-Identifier: MIT
#include "tgraph/capture/write_step.hpp"

#include <algorithm>

namespace tgraph::capture {

std::string step_misuse_line(const Recorder& rec) {
  const std::uint64_t n = rec.step_errors();
  if (n == 0) return {};
  // The step's misuses are the last ones kept (all of them unless more than kMaxMisuses
  // were seen before, when the list is full: then the first kept stands for them).
  const std::vector<Misuse>& m = rec.misuses();
  std::string line = "API misuse";
  if (!m.empty()) {
    const std::size_t back = static_cast<std::size_t>(std::min<std::uint64_t>(n, m.size()));
    line = to_string(m[m.size() - back]);
  }
  if (n > 1) line += " and " + std::to_string(n - 1) + " more misuse(s)";
  return line;
}

void append_step(TraceWriter& writer, const Recorder& rec, const StepGraph& g, bool allow_misuse) {
  if (!allow_misuse && rec.step_errors() != 0)
    throw MisuseError(step_misuse_line(rec) + "; ",
                      "the step is not written (write it anyway with {allow_misuse})",
                      kNamesFields);
  writer.append(g);
}

}  // namespace tgraph::capture
