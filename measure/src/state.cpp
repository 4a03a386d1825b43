// SPDX-License-Identifier: MIT
#include "tgraph/measure/state.hpp"

#include <algorithm>
#include <limits>
#include <unordered_map>

#include "tgraph/graph/access_check.hpp"

namespace tgraph::measure {

void set_write_order(std::vector<StateRegion>& regions, const StepGraph& g) {
  std::vector<std::uint32_t> first(g.data.size(), StateRegion::kNotWritten);
  std::vector<TaskId> last(g.data.size(), kNoTask);
  for (TaskId t = 0; t < g.tasks.size(); ++t)
    for (const Access& a : g.accesses_of(t))
      if (writes(a.mode) && a.datum < g.data.size()) {
        if (first[a.datum] == StateRegion::kNotWritten) first[a.datum] = t;
        last[a.datum] = t;
      }
  std::unordered_map<std::string, std::vector<DatumId>> by_name;
  for (DatumId d = static_cast<DatumId>(g.data.size()); d-- > 0;)
    by_name[g.data[d].name].push_back(d);
  for (StateRegion& r : regions) {
    auto it = by_name.find(r.name);
    if (it == by_name.end() || it->second.empty()) continue;
    const DatumId d = it->second.back();
    it->second.pop_back();
    r.first_write = first[d];
    r.writer = last[d] == kNoTask ? std::string() : task_label(g, last[d]);
  }
}

StateSnapshot snapshot(std::span<const StateRegion> regions) {
  StateSnapshot s;
  for (const StateRegion& r : regions) {
    s.names.push_back(r.name);
    const auto* p = static_cast<const std::uint8_t*>(r.ptr);
    s.bytes.emplace_back(p, p + (p ? r.bytes : 0));
    s.writers.push_back(r.writer);
    s.first_writes.push_back(r.first_write);
  }
  return s;
}

std::optional<StateDifference> compare(const StateSnapshot& expected, const StateSnapshot& actual) {
  std::unordered_map<std::string, std::vector<std::size_t>> in_expected;
  for (std::size_t i = expected.names.size(); i-- > 0;) in_expected[expected.names[i]].push_back(i);
  auto writer_of = [](const StateSnapshot& s, std::size_t i) {
    return i < s.writers.size() ? s.writers[i] : std::string();
  };
  std::vector<std::size_t> order(actual.names.size());
  for (std::size_t i = 0; i < order.size(); ++i) order[i] = i;
  auto first_write = [&actual](std::size_t i) {
    return i < actual.first_writes.size() ? actual.first_writes[i] : StateRegion::kNotWritten;
  };
  std::stable_sort(order.begin(), order.end(),
                   [&](std::size_t a, std::size_t b) { return first_write(a) < first_write(b); });
  for (const std::size_t i : order) {
    const std::string& name = actual.names[i];
    auto it = in_expected.find(name);
    if (it == in_expected.end() || it->second.empty())
      return StateDifference{name, 0, 0, writer_of(actual, i)};
    const std::size_t e = it->second.back();
    it->second.pop_back();
    const auto& a = expected.bytes[e];
    const auto& b = actual.bytes[i];
    if (a == b) continue;
    StateDifference d{name, 0, 0, writer_of(actual, i)};
    if (d.writer.empty()) d.writer = writer_of(expected, e);
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
  for (const auto& [name, left] : in_expected)  // in expected only
    if (!left.empty()) return StateDifference{name, 0, 0, writer_of(expected, left.back())};
  return std::nullopt;
}

std::string to_string(const StateDifference& d) {
  std::string s = "first differing datum " + d.datum + " (byte " + std::to_string(d.offset) + ", " +
                  std::to_string(d.differing_bytes) + " bytes differ)";
  if (!d.writer.empty()) s += ", last written by task " + d.writer;
  return s;
}

}  // namespace tgraph::measure
