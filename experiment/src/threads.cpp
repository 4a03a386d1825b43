// SPDX-License-Identifier: MIT
#include "tgraph/experiment/threads.hpp"

#include <algorithm>
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
