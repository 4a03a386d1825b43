// SPDX-License-Identifier: MIT
#include "tgraph/measure/state.hpp"

#include <algorithm>
#include <cmath>
#include <cstring>
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

namespace {

double value_at(const std::vector<std::uint8_t>& bytes, std::size_t i) {
  double v = 0;
  std::memcpy(&v, bytes.data() + i * sizeof v, sizeof v);
  return v;
}

}  // namespace

ValueDifference compare_values(const StateSnapshot& expected, const StateSnapshot& actual,
                               const Magnitudes* involved) {
  ValueDifference out;
  std::unordered_map<std::string, std::vector<std::size_t>> in_expected;
  for (std::size_t i = expected.names.size(); i-- > 0;) in_expected[expected.names[i]].push_back(i);
  auto refuse = [&out](std::string why) {
    if (out.incomparable.empty()) out.incomparable = std::move(why);
  };
  for (std::size_t i = 0; i < actual.names.size(); ++i) {
    const std::string& name = actual.names[i];
    auto it = in_expected.find(name);
    if (it == in_expected.end() || it->second.empty()) {
      refuse(name + " is in one state only");
      continue;
    }
    const std::vector<std::uint8_t>& a = expected.bytes[it->second.back()];
    it->second.pop_back();
    const std::vector<std::uint8_t>& b = actual.bytes[i];
    if (a == b) continue;
    if (a.size() != b.size()) {
      refuse(name + " has " + std::to_string(a.size()) + " bytes in one state, " +
             std::to_string(b.size()) + " in the other");
      continue;
    }
    if (a.size() % sizeof(double) != 0) {
      refuse(name + " is not read as doubles (" + std::to_string(a.size()) +
             " bytes) and its bytes differ");
      continue;
    }
    double diff = 0, magnitude = 0;
    for (std::size_t k = 0; k < a.size() / sizeof(double); ++k) {
      const double x = value_at(a, k), y = value_at(b, k);
      if (std::memcmp(&x, &y, sizeof x) == 0) {
        if (std::isfinite(x)) magnitude = std::max(magnitude, std::abs(x));
        continue;
      }
      ++out.differing_values;
      if (!std::isfinite(x) || !std::isfinite(y)) {
        refuse(name + " value " + std::to_string(k) + " is " + std::to_string(x) + " in one state, " +
               std::to_string(y) + " in the other");
        continue;
      }
      magnitude = std::max({magnitude, std::abs(x), std::abs(y)});
      diff = std::max(diff, std::abs(x - y));
    }
    if (involved != nullptr) {
      const auto m = involved->find(name);
      if (m != involved->end()) magnitude = std::max(magnitude, m->second);
    }
    if (diff > out.max_abs_diff) {
      out.max_abs_diff = diff;
      out.max_abs_datum = name;
    }
    const double rel = magnitude > 0 ? diff / magnitude : 0;
    if (rel > out.max_rel_diff) {
      out.max_rel_diff = rel;
      out.max_rel_datum = name;
    }
  }
  for (const auto& [name, left] : in_expected)
    if (!left.empty()) refuse(name + " is in one state only");
  return out;
}

void MagnitudeObserver::on_step_begin(const ExecGraph& exec, std::uint32_t, std::int64_t) {
  exec_ = &exec;
  current_ = regions_();
  std::unordered_map<std::string, const StateRegion*> by_name;
  for (const StateRegion& r : current_)
    if (r.ptr != nullptr && r.bytes % sizeof(double) == 0) by_name.emplace(r.name, &r);
  by_datum_.assign(exec.graph.data.size(), nullptr);
  for (DatumId d = 0; d < exec.graph.data.size(); ++d) {
    const auto it = by_name.find(exec.graph.data[d].name);
    if (it != by_name.end() && it->second->bytes == exec.graph.data[d].bytes)
      by_datum_[d] = it->second;
  }
}

void MagnitudeObserver::on_end(std::uint32_t, TaskId task, std::uint32_t, std::int64_t) {
  if (exec_ == nullptr || task >= exec_->graph.tasks.size()) return;
  for (const Access& a : exec_->graph.accesses_of(task)) {
    if (!writes(a.mode) || a.datum >= by_datum_.size() || by_datum_[a.datum] == nullptr) continue;
    const StateRegion& r = *by_datum_[a.datum];
    const auto* p = static_cast<const std::uint8_t*>(r.ptr);
    double& m = magnitudes_[r.name];
    for (std::uint64_t k = 0; k < r.bytes / sizeof(double); ++k) {
      double v = 0;
      std::memcpy(&v, p + k * sizeof v, sizeof v);
      if (std::isfinite(v)) m = std::max(m, std::abs(v));
    }
  }
}

double reduction_order_bound(std::uint64_t longest_reduction, std::uint64_t rounds) {
  const double n1 = static_cast<double>(longest_reduction > 0 ? longest_reduction - 1 : 0);
  const double gamma = n1 * kUnitRoundoff / (1 - n1 * kUnitRoundoff);
  return static_cast<double>(rounds) * 2 * gamma;
}

std::uint64_t longest_reduction(const StepGraph& g) {
  std::vector<std::uint64_t> writers(g.data.size(), 0);
  for (const Access& a : g.accesses)
    if (a.mode == AccessMode::CW && a.datum < writers.size()) ++writers[a.datum];
  std::uint64_t most = 0;
  for (const std::uint64_t w : writers) most = std::max(most, w);
  return most + 1;
}

}  // namespace tgraph::measure
