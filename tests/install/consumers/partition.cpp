// SPDX-License-Identifier: MIT
// tgraph::partition: METIS and Scotch (the libraries the package must link) on two processors.
#include <cstdio>

#include "fork_join.hpp"
#include "tgraph/graph/assignment.hpp"
#include "tgraph/partition/strategy.hpp"

int main() {
  using consumer::expect;
  const tgraph::StepGraph g = consumer::fork_join();
  for (const char* method : {"metis", "scotch"}) {
    const tgraph::partition::Result r =
        tgraph::partition::make_strategy(method)->partition(g, 2, {}, {});
    expect(tgraph::validate(g, r.assignment, 2).empty(), std::string(method) + ": valid");
    std::uint32_t on[2] = {0, 0};
    for (tgraph::ProcId p : r.assignment.proc) ++on[p];
    // 9 tasks of equal cost: within 3% imbalance of 4.5, each side gets 4 or 5.
    expect(on[0] >= 4 && on[1] >= 4, std::string(method) + ": balanced");
    std::printf("partition %s: %u + %u tasks\n", method, on[0], on[1]);
  }
  return 0;
}
