// SPDX-License-Identifier: MIT
#include "tgraph/experiment/threads.hpp"

#include <algorithm>
#include <charconv>
#include <string>

#include "tgraph/graph/error.hpp"

namespace tgraph::experiment {
namespace {

std::uint32_t parse_count(std::string_view item, std::string_view text, std::string_view flag) {
  std::uint64_t v = 0;
  const char* end = item.data() + item.size();
  const auto [ptr, ec] = std::from_chars(item.data(), end, v);
  if (item.empty() || ec != std::errc() || ptr != end)
    throw UsageError(std::string(flag) + " " + std::string(text) + ": '" + std::string(item) +
                     "' is not a thread count (expected e.g. 1,2,4 or 1-8)");
  if (v == 0 || v > kMaxThreads)
    throw UsageError(std::string(flag) + " " + std::string(text) + ": " + std::string(item) +
                     " threads is out of range (expected 1 to " + std::to_string(kMaxThreads) +
                     ")");
  return static_cast<std::uint32_t>(v);
}

}  // namespace

std::vector<std::uint32_t> parse_thread_list(std::string_view text, std::string_view flag) {
  std::vector<std::uint32_t> out;
  std::size_t at = 0;
  while (at <= text.size()) {
    const std::size_t comma = std::min(text.find(',', at), text.size());
    const std::string_view item = text.substr(at, comma - at);
    const std::size_t dash = item.find('-');
    if (dash == std::string_view::npos) {
      out.push_back(parse_count(item, text, flag));
    } else {
      const std::uint32_t lo = parse_count(item.substr(0, dash), text, flag);
      const std::uint32_t hi = parse_count(item.substr(dash + 1), text, flag);
      if (hi < lo)
        throw UsageError(std::string(flag) + " " + std::string(text) + ": range '" +
                         std::string(item) + "' goes down (expected low-high)");
      for (std::uint32_t k = lo; k <= hi; ++k) out.push_back(k);
    }
    at = comma + 1;
  }
  std::sort(out.begin(), out.end());
  out.erase(std::unique(out.begin(), out.end()), out.end());
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
