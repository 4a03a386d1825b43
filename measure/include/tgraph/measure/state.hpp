// SPDX-License-Identifier: MIT
// The state of an engine as named byte regions: snapshots and their bit-for-bit comparison
// (the check of a live run).
#pragma once

#include <cstdint>
#include <optional>
#include <span>
#include <string>
#include <utility>
#include <vector>

#include "tgraph/graph/step_graph.hpp"

namespace tgraph::measure {

/// One named piece of state (a datum's storage).
struct StateRegion {
  StateRegion() = default;
  /// `{name, ptr, bytes}` as before the writer was added (braces keep working).
  StateRegion(std::string n, const void* p, std::uint64_t b)
      : name(std::move(n)), ptr(p), bytes(b) {}
  /// first_write: kNotWritten when unknown or not written.
  static constexpr std::uint32_t kNotWritten = 0xffffffffu;
  std::string name;
  const void* ptr = nullptr;
  std::uint64_t bytes = 0;
  /// Position in the engine's last recorded step of the first task that writes it
  /// (set_write_order), the order in which compare() looks for the first difference.
  std::uint32_t first_write = kNotWritten;
  /// The task that last wrote it in that step (task_label: "kind of object"); empty when
  /// unknown or not written.
  std::string writer;
};

/// Sets each region's first_write and writer from `g`, the engine's last recorded step
/// (regions matched to `g`'s data by name); the regions keep their order. compare() then
/// names the datum whose bytes differ first in program order of the writes.
void set_write_order(std::vector<StateRegion>& regions, const StepGraph& g);

/// A copy of the bytes of some regions.
struct StateSnapshot {
  std::vector<std::string> names;
  std::vector<std::vector<std::uint8_t>> bytes;
  std::vector<std::string> writers;         ///< StateRegion::writer, by region
  std::vector<std::uint32_t> first_writes;  ///< StateRegion::first_write, by region
};

/// Copies the regions' bytes.
StateSnapshot snapshot(std::span<const StateRegion> regions);

/// First difference between two snapshots of the same regions.
struct StateDifference {
  StateDifference() = default;
  StateDifference(std::string d, std::uint64_t o, std::uint64_t n, std::string w = {})
      : datum(std::move(d)), offset(o), differing_bytes(n), writer(std::move(w)) {}
  std::string datum;                  ///< name of the first differing region
  std::uint64_t offset = 0;           ///< first differing byte in it
  std::uint64_t differing_bytes = 0;  ///< in that region
  std::string writer;                 ///< the task that last wrote it (empty: unknown)
};

/// nullopt when equal bit for bit. `actual`'s regions are taken in the order of their first
/// write (set_write_order; unwritten ones after, in their order) and found in `expected` by
/// name (the k-th of a repeated name with the k-th): the first difference is the datum whose
/// bytes differ first in program order of the writes; a region missing from either side
/// differs.
std::optional<StateDifference> compare(const StateSnapshot& expected, const StateSnapshot& actual);
/// "first differing datum <datum> (byte <offset>, <differing_bytes> bytes differ), last
/// written by task <writer>".
std::string to_string(const StateDifference& d);

}  // namespace tgraph::measure
