// SPDX-License-Identifier: MIT
// The recorder's incremental edge derivation on the dynamic scene `falling`: every step's
// edges equal a from-scratch derivation, edge for edge.
#include <gtest/gtest.h>

#include <vector>

#include "test_util.hpp"
#include "tgraph/graph/incremental.hpp"

namespace tgraph::samples {
namespace {

TEST(IncrementalEdges, EqualFromScratchOnEveryStepOfFalling) {
  auto s = make_scene("falling");
  capture::Recorder rec(capture::Mode::kCapture);
  ASSERT_EQ(s->default_steps(), 300);
  std::vector<Contact> prev;
  std::vector<ObjectId> prev_narrow;
  int changes = 0, merged_or_split = 0;
  std::size_t prev_loops = 0;
  for (int k = 0; k < s->default_steps(); ++k) {
    s->step(rec);
    const StepGraph g = rec.end_step();
    const EdgeUpdate u = rec.last_edge_update();
    StepGraph reference = g;
    reference.derive_edges();
    ASSERT_EQ(g.edges, reference.edges) << "step " << k;
    ASSERT_EQ(g.carried_edges, reference.carried_edges) << "step " << k;
    EXPECT_EQ(u.incremental, k > 0) << "step " << k;
    EXPECT_EQ(u.edges, g.edges.size() + g.carried_edges.size());
    // The narrow-phase tasks of collision detection (one per body pair the broad phase keeps)
    // change the structure too, a step or more before the contacts they find.
    std::vector<ObjectId> narrow;
    for (TaskId t = 0; t < g.tasks.size(); ++t)
      if (g.kind_name(t) == "collidePair" || g.kind_name(t) == "collideFloor") narrow.push_back(g.tasks[t].object);
    const bool narrow_changed = k > 0 && narrow != prev_narrow;
    prev_narrow = std::move(narrow);
    if (k > 0 && (g.contacts != prev || narrow_changed)) {
      if (g.contacts != prev) ++changes;
      if (g.loops.size() != prev_loops) ++merged_or_split;
      // Only the data of the bodies the change touched are derived again.
      EXPECT_GT(u.data_rederived, 0u) << "step " << k;
      EXPECT_GT(u.data_reused, u.data_rederived) << "step " << k;
      EXPECT_GT(u.edges_reused, 0u) << "step " << k;
    } else if (k > 0) {
      EXPECT_EQ(u.data_rederived, 0u) << "step " << k;
      EXPECT_EQ(u.edges_reused, u.edges) << "step " << k;
    }
    prev = g.contacts;
    prev_loops = g.loops.size();
  }
  EXPECT_GT(changes, 10);
  EXPECT_GT(merged_or_split, 5);
  EXPECT_EQ(rec.errors(), 0u);
}

TEST(IncrementalEdges, FromScratchModeGivesTheSameEdges) {
  auto a = make_scene("falling");
  auto b = make_scene("falling");
  capture::Recorder inc(capture::Mode::kCapture), full(capture::Mode::kCapture);
  full.set_incremental_edges(false);
  for (int k = 0; k < 60; ++k) {
    a->step(inc);
    b->step(full);
    const StepGraph gi = inc.end_step();
    const StepGraph gf = full.end_step();
    ASSERT_EQ(gi.edges, gf.edges) << "step " << k;
    ASSERT_EQ(gi.carried_edges, gf.carried_edges) << "step " << k;
    EXPECT_FALSE(full.last_edge_update().incremental);
  }
}

}  // namespace
}  // namespace tgraph::samples
