// SPDX-License-Identifier: MIT
#include "tgraph/experiment/metg.hpp"

#include <gtest/gtest.h>

#include <set>
#include <utility>

#include "tgraph/graph/error.hpp"

namespace tgraph::experiment {
namespace {

/// (from point, to point) of the edges between consecutive steps of a width-w shape.
std::set<std::pair<std::uint32_t, std::uint32_t>> links(const StepGraph& g, std::uint32_t w,
                                                        std::uint32_t step) {
  std::set<std::pair<std::uint32_t, std::uint32_t>> out;
  for (const Edge& e : g.edges)
    if (e.to / w == step) {
      EXPECT_EQ(e.from / w + 1, step) << "an edge skips a step";
      out.insert({e.from % w, e.to % w});
    }
  return out;
}

TEST(MetgGraph, TrivialHasNoEdgesAndOneTaskPerPointAndStep) {
  const StepGraph g = metg_graph(MetgShape::kTrivial, 4, 3, 1000);
  EXPECT_EQ(g.tasks.size(), 12u);
  EXPECT_TRUE(g.edges.empty());
  for (const Task& t : g.tasks) EXPECT_EQ(t.cost_ns, 1000u);
}

TEST(MetgGraph, StencilLinksEachPointToItsNeighboursOfThePreviousStep) {
  const StepGraph g = metg_graph(MetgShape::kStencil, 4, 3, 1000);
  const auto l = links(g, 4, 2);
  const std::set<std::pair<std::uint32_t, std::uint32_t>> want = {
      {0, 0}, {1, 0}, {0, 1}, {1, 1}, {2, 1}, {1, 2}, {2, 2}, {3, 2}, {2, 3}, {3, 3}};
  EXPECT_EQ(l, want);
}

TEST(MetgGraph, FftPairsPointsAtDistancesThatCycleOverTheStages) {
  const StepGraph g = metg_graph(MetgShape::kFft, 8, 5, 1000);
  for (std::uint32_t step = 1; step < 5; ++step) {
    const std::uint32_t d = 1u << ((step - 1) % 3);
    for (const auto& [from, to] : links(g, 8, step))
      EXPECT_TRUE(from == to || (from ^ to) == d) << "step " << step << ": " << from << "->" << to;
    EXPECT_EQ(links(g, 8, step).size(), 16u);  // itself and its partner, for 8 points
  }
}

TEST(MetgGraph, RandomNearestKeepsEachChainAndStaysWithinRadiusTwo) {
  const StepGraph g = metg_graph(MetgShape::kRandomNearest, 16, 6, 1000);
  std::size_t others = 0;
  for (std::uint32_t step = 1; step < 6; ++step) {
    const auto l = links(g, 16, step);
    for (std::uint32_t i = 0; i < 16; ++i) EXPECT_TRUE(l.count({i, i})) << "point " << i;
    for (const auto& [from, to] : l) {
      EXPECT_LE(from > to ? from - to : to - from, 2u);
      others += from != to;
    }
  }
  EXPECT_GT(others, 0u);
  EXPECT_LT(others, 5u * 16u * 4u);  // a subset of the neighbours, not all of them
  // Seeded: the same graph every time.
  EXPECT_EQ(metg_graph(MetgShape::kRandomNearest, 16, 6, 1000).edges.size(), g.edges.size());
}

TEST(MetgGraph, RejectsBars64WhichIsCaptured) {
  EXPECT_THROW(metg_graph(MetgShape::kBars64, 4, 4, 1000), UsageError);
  EXPECT_EQ(to_string(MetgShape::kRandomNearest), "random_nearest");
}

}  // namespace
}  // namespace tgraph::experiment
