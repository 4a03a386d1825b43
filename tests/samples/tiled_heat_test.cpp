// SPDX-License-Identifier: MIT
// The test engine of --verify-accesses in capture mode: its two planted mistakes named, and
// 20 seeded variants with one access dropped or given a wrong mode: every dropped or
// weakened write found, every dropped read found where docs/instrumenting.md says reads are
// visible (a datum of non-zero doubles whose value reaches the task's written data).
#include "tgraph/samples/tiled_heat.hpp"

#include <gtest/gtest.h>

#include <random>
#include <string>
#include <vector>

namespace tgraph::samples {
namespace {

std::vector<AccessFinding> capture_verified(TiledHeatOptions o, int steps, StepGraph* first = nullptr) {
  TiledHeat heat(std::move(o));
  capture::Recorder rec(capture::Mode::kCapture);
  heat.declare(rec);
  rec.set_verify_accesses(true);
  for (int s = 0; s < steps; ++s) {
    rec.begin_step();
    heat.step(rec);
    StepGraph g = rec.end_step();
    if (s == 0 && first) *first = std::move(g);
  }
  EXPECT_EQ(rec.errors(), 0u);
  return rec.access_findings();
}

TEST(TiledHeat, ConvergesAndConservesNoMoreHeatThanItHad) {
  TiledHeat heat;
  capture::Recorder rec(capture::Mode::kCapture);
  heat.declare(rec);
  const double before = heat.total();
  rec.begin_step();
  heat.step(rec);
  const StepGraph g = rec.end_step();
  ASSERT_EQ(g.loops.size(), 1u);
  EXPECT_GT(g.loops[0].iterations, 3u);
  EXPECT_LT(g.loops[0].iterations, 60u);  // converged before the maximum
  EXPECT_LT(heat.total(), before);        // heat leaves through the cold border
  EXPECT_GT(heat.total(), 0.5 * before);
}

TEST(TiledHeat, CaptureNamesThePlantedMistakesAndNothingWhenRight) {
  TiledHeatOptions wrong;
  wrong.plant = HeatPlant::kWrongMode;
  std::vector<AccessFinding> f = capture_verified(wrong, 2);
  ASSERT_EQ(f.size(), 1u);
  EXPECT_EQ(to_string(f[0]), "task direction of tile(1,2) wrote tile(1,2).p, declared R");
  TiledHeatOptions halo;
  halo.plant = HeatPlant::kMissingHalo;
  f = capture_verified(halo, 2);
  ASSERT_EQ(f.size(), 1u);
  EXPECT_EQ(to_string(f[0]), "task matvec of tile(1,1) read tile(0,1).p, declared none");
  EXPECT_TRUE(capture_verified({}, 2).empty());
}

TEST(TiledHeat, TwentySeededDroppedOrWeakenedAccessesAreFound) {
  StepGraph g;
  capture_verified({}, 1, &g);
  std::vector<TaskId> tasks;  // every task but the loop's break (not the engine's)
  for (TaskId t = 0; t < g.tasks.size(); ++t)
    if (g.kinds[g.tasks[t].kind] != "loop.break") tasks.push_back(t);
  int writes_planted = 0, reads_planted = 0;
  for (std::uint32_t seed = 1; seed <= 20; ++seed) {
    std::mt19937 rng(seed);
    const TaskId t = tasks[std::uniform_int_distribution<std::size_t>(0, tasks.size() - 1)(rng)];
    const std::span<const Access> acc = g.accesses_of(t);
    const auto a = static_cast<std::uint32_t>(
        std::uniform_int_distribution<std::size_t>(0, acc.size() - 1)(rng));
    const bool wrote = writes(acc[a].mode);
    const bool drop = !wrote || std::uniform_int_distribution<int>(0, 1)(rng) == 0;
    TiledHeatOptions o;
    o.mutation = AccessMutation{t, a, drop ? std::nullopt : std::optional(AccessMode::R)};
    const std::vector<AccessFinding> f = capture_verified(o, 3);
    const std::string task = task_label(g, t), datum = g.data[acc[a].datum].name;
    const std::string what = "seed " + std::to_string(seed) + ": " + task + ", " + datum +
                             (drop ? " dropped" : " declared R");
    if (wrote) {
      ++writes_planted;
      ASSERT_EQ(f.size(), 1u) << what;
      EXPECT_EQ(f[0], (AccessFinding{task, datum, AccessFound::kWrite, drop ? "none" : "R"}))
          << what;
    } else if (g.kinds[g.tasks[t].kind] == "beta" && datum == "solver.b2") {
      // b2 only decides a comparison that a 2^-12 change does not flip: invisible (docs).
      EXPECT_TRUE(f.empty()) << what;
    } else {
      ++reads_planted;
      ASSERT_EQ(f.size(), 1u) << what;
      EXPECT_EQ(f[0], (AccessFinding{task, datum, AccessFound::kRead, "none"})) << what;
    }
  }
  EXPECT_GT(writes_planted, 3);  // the seeds plant both kinds
  EXPECT_GT(reads_planted, 3);
}

}  // namespace
}  // namespace tgraph::samples
