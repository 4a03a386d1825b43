// SPDX-License-Identifier: MIT
// The command line's thread lists, such as 1-4,8,16: the modules take the counts.
#pragma once

#include <charconv>
#include <string_view>

#include "commands.hpp"
#include "tgraph/experiment/threads.hpp"

namespace tgraph::app {

/// Adds `flag`: thread counts and ranges such as 1-4,8,16, each 1 to experiment::kMaxThreads,
/// into `out` (the module sorts them); UsageError naming the flag for anything else (an empty
/// item, a range that goes down, a count out of range).
inline void add_thread_list(CLI::App* cmd, const std::string& flag,
                            std::vector<std::uint32_t>& out, const std::string& help) {
  cmd->add_option_function<std::string>(flag, [flag, &out](const std::string& text) {
    const auto count = [&](std::string_view s, std::uint32_t least) {  // least <= count <= max
      std::uint32_t v = 0;
      const auto [end, ec] = std::from_chars(s.data(), s.data() + s.size(), v);
      if (s.empty() || ec != std::errc() || end != s.data() + s.size() || v < least ||
          v > experiment::kMaxThreads)
        throw UsageError(flag + " " + text + ": expected counts from 1 to " +
                         std::to_string(experiment::kMaxThreads) + ", such as 1-4,8");
      return v;
    };
    out.clear();
    for (std::string_view rest = text;;) {
      const std::string_view item = rest.substr(0, rest.find(','));
      const std::size_t dash = std::min(item.find('-'), item.size());
      const std::uint32_t lo = count(item.substr(0, dash), 1);
      const std::uint32_t hi = dash == item.size() ? lo : count(item.substr(dash + 1), lo);
      for (std::uint32_t k = lo; k <= hi; ++k) out.push_back(k);
      if (item.size() == rest.size()) break;
      rest.remove_prefix(item.size() + 1);
    }
  }, help);
}

}  // namespace tgraph::app
