// SPDX-License-Identifier: MIT
#include "tgraph/experiment/threads.hpp"

#include <algorithm>
#include <charconv>
#include <string>

#include "tgraph/graph/error.hpp"

namespace tgraph::experiment {

std::vector<std::uint32_t> thread_counts(std::vector<std::uint32_t> threads) {
  for (std::uint32_t k : threads)
    if (k == 0 || k > kMaxThreads)
      throw OptionError("threads", std::to_string(k) + " threads is out of range (expected 1 to " +
                                       std::to_string(kMaxThreads) + ")");
  std::sort(threads.begin(), threads.end());
  threads.erase(std::unique(threads.begin(), threads.end()), threads.end());
  return threads;
}

std::vector<std::uint32_t> parse_thread_list(std::string_view text) {
  const auto count = [text](std::string_view s, std::uint32_t least) {  // least <= count <= max
    std::uint32_t v = 0;
    const auto [end, ec] = std::from_chars(s.data(), s.data() + s.size(), v);
    if (s.empty() || ec != std::errc() || end != s.data() + s.size() || v < least ||
        v > kMaxThreads)
      throw UsageError("", "{threads} " + std::string(text) + ": expected counts from 1 to " +
                               std::to_string(kMaxThreads) + ", such as 1-4,8",
                       kNamesFields);
    return v;
  };
  std::vector<std::uint32_t> out;
  for (std::string_view rest = text;;) {
    const std::string_view item = rest.substr(0, rest.find(','));
    const std::size_t dash = std::min(item.find('-'), item.size());
    const std::uint32_t lo = count(item.substr(0, dash), 1);
    const std::uint32_t hi = dash == item.size() ? lo : count(item.substr(dash + 1), lo);
    for (std::uint32_t k = lo; k <= hi; ++k) out.push_back(k);
    if (item.size() == rest.size()) break;
    rest.remove_prefix(item.size() + 1);
  }
  return out;
}

std::vector<std::uint32_t> default_thread_list(std::uint32_t cores, std::uint32_t max_threads) {
  std::vector<std::uint32_t> out;
  cores = std::max(cores, 1u);
  for (std::uint32_t k = 1; k <= cores; ++k) out.push_back(k);
  for (std::uint32_t k = 2; k <= max_threads; k *= 2)
    if (k > cores) out.push_back(k);
  return out;
}

std::vector<std::uint32_t> ThreadPlan::all() const {
  std::vector<std::uint32_t> out = measured;
  out.insert(out.end(), predicted.begin(), predicted.end());
  return out;
}

ThreadPlan split_threads(std::span<const std::uint32_t> threads, std::uint32_t cores) {
  ThreadPlan p;
  for (std::uint32_t k : threads) (k <= cores ? p.measured : p.predicted).push_back(k);
  return p;
}

}  // namespace tgraph::experiment
