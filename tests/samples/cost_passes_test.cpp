// SPDX-License-Identifier: MIT
// Capture cost passes do not change the physics: the state after a capture with passes is
// the state after one without, bit for bit, on a scene with contacts and CG loops.
#include <gtest/gtest.h>

#include <cstring>
#include <string>

#include "tgraph/capture/recorder.hpp"
#include "tgraph/samples/scene.hpp"

namespace tgraph::samples {
namespace {

TEST(CostPasses, LeaveTheSceneStateBitForBitAsOnePass) {
  for (const std::string name : {"fig2", "falling"}) {
    auto once = make_scene(name), three = make_scene(name);
    capture::Recorder a(capture::Mode::kCapture), b(capture::Mode::kCapture);
    b.set_cost_passes(3);
    std::uint64_t tasks = 0;
    for (int s = 0; s < 6; ++s) {
      once->step(a);
      const StepGraph ga = a.end_step();
      three->step(b);
      const StepGraph gb = b.end_step();
      ASSERT_TRUE(ga.same_structure(gb)) << name << " step " << s;
      for (LoopId l = 0; l < ga.loops.size(); ++l)
        EXPECT_EQ(ga.loops[l].iterations, gb.loops[l].iterations) << name << " step " << s;
      tasks += gb.tasks.size();
    }
    ASSERT_EQ(once->bodies().size(), three->bodies().size());
    for (std::size_t i = 0; i < once->bodies().size(); ++i)
      for (VecId id : {VecId::kX, VecId::kV}) {
        const StateVec& x = static_cast<const Body&>(*once->bodies()[i]).vec(id);
        const StateVec& y = static_cast<const Body&>(*three->bodies()[i]).vec(id);
        ASSERT_EQ(x.size(), y.size());
        EXPECT_EQ(std::memcmp(x.data(), y.data(), static_cast<std::size_t>(x.size()) * sizeof(double)), 0)
            << name << ": body " << i << " " << to_string(id) << " differs";
      }
    EXPECT_EQ(a.errors(), 0u);
    EXPECT_EQ(b.errors(), 0u);
    EXPECT_LT(b.single_pass_runs(), tasks) << name << ": most tasks are repeated";
  }
}

}  // namespace
}  // namespace tgraph::samples
