// SPDX-License-Identifier: MIT
#include "tgraph/measure/state.hpp"

#include <algorithm>

namespace tgraph::measure {

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

std::string to_string(const StateDifference& d) {
  return "first differing datum " + d.datum + " (byte " + std::to_string(d.offset) + ", " +
         std::to_string(d.differing_bytes) + " bytes differ)";
}

}  // namespace tgraph::measure
