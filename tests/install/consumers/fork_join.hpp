// SPDX-License-Identifier: MIT
// The graph the consumers share: kWidth independent "scale" tasks, each updating its own
// datum x_i (RW, 1 µs), then one "sum" task reading every x_i and writing the total (1 µs).
// Analytically: kWidth + 1 tasks, kWidth RAW edges, work (kWidth + 1) µs, span 2 µs.
#pragma once

#include <cstdio>
#include <cstdlib>
#include <string>
#include <vector>

#include "tgraph/graph/step_graph.hpp"

namespace consumer {

inline constexpr std::uint32_t kWidth = 8;
inline constexpr std::uint64_t kCostNs = 1000;

inline tgraph::StepGraph fork_join() {
  tgraph::StepGraph g;
  const tgraph::KindId scale = g.intern_kind("scale"), sum = g.intern_kind("sum");
  std::vector<tgraph::Access> all;
  for (std::uint32_t i = 0; i < kWidth; ++i) {
    g.data.push_back({"x" + std::to_string(i), tgraph::kNoObject, sizeof(double)});
    const tgraph::Access rw{i, tgraph::AccessMode::RW};
    g.add_task(scale, tgraph::kNoObject, {&rw, 1}, kCostNs, i + 1);
    all.push_back({i, tgraph::AccessMode::R});
  }
  g.data.push_back({"total", tgraph::kNoObject, sizeof(double)});
  all.push_back({kWidth, tgraph::AccessMode::W});
  g.add_task(sum, tgraph::kNoObject, all, kCostNs, kWidth + 1);
  g.derive_edges();
  return g;
}

/// Exits 1 with a message when `ok` is false.
inline void expect(bool ok, const std::string& what) {
  if (ok) return;
  std::fprintf(stderr, "consumer: check failed: %s\n", what.c_str());
  std::exit(1);
}

}  // namespace consumer
