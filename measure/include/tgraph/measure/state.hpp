// SPDX-License-Identifier: MIT
// The state of an engine as named byte regions: snapshots and their bit-for-bit comparison
// (the check of a live run).
#pragma once

#include <cstdint>
#include <optional>
#include <span>
#include <string>
#include <vector>

namespace tgraph::measure {

/// One named piece of state (a datum's storage).
struct StateRegion {
  std::string name;
  const void* ptr = nullptr;
  std::uint64_t bytes = 0;
};

/// A copy of the bytes of some regions.
struct StateSnapshot {
  std::vector<std::string> names;
  std::vector<std::vector<std::uint8_t>> bytes;
};

/// Copies the regions' bytes.
StateSnapshot snapshot(std::span<const StateRegion> regions);

/// First difference between two snapshots of the same regions.
struct StateDifference {
  std::string datum;                  ///< name of the first differing region
  std::uint64_t offset = 0;           ///< first differing byte in it
  std::uint64_t differing_bytes = 0;  ///< in that region
};

/// nullopt when equal bit for bit.
std::optional<StateDifference> compare(const StateSnapshot& expected, const StateSnapshot& actual);
/// "first differing datum <datum> (byte <offset>, <differing_bytes> bytes differ)".
std::string to_string(const StateDifference& d);

}  // namespace tgraph::measure
