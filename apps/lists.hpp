// SPDX-License-Identifier: MIT
// The command line's thread lists, such as 1-4,8,16: the modules take the counts.
#pragma once

#include <charconv>
#include <string_view>

#include "commands.hpp"
#include "tgraph/experiment/threads.hpp"

namespace tgraph::app {

/// "1-4,8,16" -> 1, 2, 3, 4, 8, 16, ascending, without duplicates; nullopt for an empty item,
/// a count outside 1..`max`, a range that goes down or anything not a number.
inline std::optional<std::vector<std::uint32_t>> parse_counts(std::string_view text,
                                                              std::uint32_t max) {
  const auto count = [max](std::string_view s, std::uint32_t& v) {
    const auto [end, ec] = std::from_chars(s.data(), s.data() + s.size(), v);
    return !s.empty() && ec == std::errc() && end == s.data() + s.size() && v >= 1 && v <= max;
  };
  std::vector<std::uint32_t> out;
  for (std::size_t at = 0; at <= text.size();) {
    const std::size_t comma = std::min(text.find(',', at), text.size());
    const std::string_view item = text.substr(at, comma - at);
    const std::size_t dash = std::min(item.find('-'), item.size());
    std::uint32_t lo = 0, hi = 0;
    if (!count(item.substr(0, dash), lo) ||
        !count(dash == item.size() ? item : item.substr(dash + 1), hi) || hi < lo)
      return std::nullopt;
    for (std::uint32_t k = lo; k <= hi; ++k) out.push_back(k);
    at = comma + 1;
  }
  std::sort(out.begin(), out.end());
  out.erase(std::unique(out.begin(), out.end()), out.end());
  return out;
}

/// Adds `flag`, a thread list into `out`; UsageError naming the flag for anything else.
inline void add_thread_list(CLI::App* cmd, const std::string& flag,
                            std::vector<std::uint32_t>& out, const std::string& help) {
  cmd->add_option_function<std::string>(flag, [flag, &out](const std::string& text) {
    const auto ks = parse_counts(text, experiment::kMaxThreads);
    if (!ks)
      throw UsageError(flag + " " + text + ": expected counts from 1 to " +
                       std::to_string(experiment::kMaxThreads) + ", such as 1-4,8");
    out = *ks;
  }, help);
}

}  // namespace tgraph::app
