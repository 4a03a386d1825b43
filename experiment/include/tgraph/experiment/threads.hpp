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

/// `threads` ascending, without duplicates; tgraph::OptionError on `threads` for a count of 0
/// or above kMaxThreads.
std::vector<std::uint32_t> thread_counts(std::vector<std::uint32_t> threads);

/// The counts of a list such as "1-4,8,16" (counts and ranges, each 1 to kMaxThreads), in
/// its order (thread_counts sorts them). A UsageError naming the field `threads` for anything
/// else: an empty item, a range that goes down, a count out of range.
std::vector<std::uint32_t> parse_thread_list(std::string_view text);

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
