// SPDX-License-Identifier: MIT
#include "tgraph/replay/live.hpp"

#include <cstring>

#include "tgraph/replay/lowering.hpp"

namespace tgraph::replay {

void ProgramWorkload::run(const TaskRun& r) {
  if (r.origin == kNoTask) return;  // no reducers in kSerialize lowering
  const auto& body = bodies_[r.origin];
  if (body) body();
}

bool ProgramWorkload::stop_after(LoopId loop, std::uint32_t) { return conditions_[loop](); }

StateSnapshot snapshot(std::span<const StateRegion> regions) {
  StateSnapshot s;
  for (const StateRegion& r : regions) {
    s.names.push_back(r.name);
    const auto* p = static_cast<const std::uint8_t*>(r.ptr);
    s.bytes.emplace_back(p, p + (p ? r.bytes : 0));
  }
  return s;
}

std::optional<StateDifference> compare(const StateSnapshot& expected, const StateSnapshot& actual) {
  const std::size_t n = std::max(expected.bytes.size(), actual.bytes.size());
  for (std::size_t i = 0; i < n; ++i) {
    const std::string& name = i < expected.names.size() ? expected.names[i] : actual.names[i];
    if (i >= expected.bytes.size() || i >= actual.bytes.size()) return StateDifference{name, 0, 0};
    const auto& a = expected.bytes[i];
    const auto& b = actual.bytes[i];
    if (a == b) continue;
    StateDifference d{name, 0, 0};
    const std::size_t m = std::min(a.size(), b.size());
    bool found = false;
    for (std::size_t j = 0; j < m; ++j)
      if (a[j] != b[j]) {
        if (!found) d.offset = j;
        found = true;
        ++d.differing_bytes;
      }
    d.differing_bytes += std::max(a.size(), b.size()) - m;
    if (!found) d.offset = m;
    return d;
  }
  return std::nullopt;
}

}  // namespace tgraph::replay
