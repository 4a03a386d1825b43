// SPDX-License-Identifier: MIT
// Thread counts of an experiment: those measured on this machine (up to its cores) and
// those only predicted by the simulator (beyond them), kept apart.
#pragma once

#include <cstdint>
#include <span>
#include <string_view>
#include <vector>

namespace tgraph::experiment {

/// Largest thread count an experiment accepts.
inline constexpr std::uint32_t kMaxThreads = 1024;

/// Parses a thread list such as "1,2,4", "1-8" or "1-4,8,16": sorted, without duplicates.
/// Throws tgraph::UsageError naming `flag` and the bad item (empty list, 0, a reversed
/// range, a count above kMaxThreads, anything not a number).
std::vector<std::uint32_t> parse_thread_list(std::string_view text,
                                             std::string_view flag = "--threads");

/// The default list: every count from 1 to `cores`, then the powers of two above `cores`
/// up to `max_threads` (2 cores, 64: 1, 2, 4, 8, 16, 32, 64).
std::vector<std::uint32_t> default_thread_list(std::uint32_t cores, std::uint32_t max_threads = 64);

/// Thread counts split by how their figures are obtained.
struct ThreadPlan {
  std::vector<std::uint32_t> measured;   ///< <= cores: run (live and replay) and predicted
  std::vector<std::uint32_t> predicted;  ///< > cores: predicted by the simulator only
  /// Every count, ascending (measured then predicted).
  std::vector<std::uint32_t> all() const;
};

/// Splits `threads` (ascending) at `cores`: counts up to it are measured, the others only
/// predicted.
ThreadPlan split_threads(std::span<const std::uint32_t> threads, std::uint32_t cores);

}  // namespace tgraph::experiment
