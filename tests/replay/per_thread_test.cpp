// SPDX-License-Identifier: MIT
// Per-thread temporaries (ReduceScope::kPerThread) for the dynamic policies' cumulative
// writes: one temporary per thread and group, whatever its writers; sums of doubles equal
// the sequential ones within rounding (the grouping of the writers is the run's).
#include <gtest/gtest.h>

#include <cmath>
#include <vector>

#include "random_graph.hpp"
#include "tgraph/graph/lowering.hpp"
#include "tgraph/replay/executor.hpp"
#include "tgraph/replay/synthetic.hpp"

namespace tgraph::replay {
namespace {

constexpr int kWriters = 40;

/// A task writing d0, then `kWriters` tasks adding to d1 (CW, each also reading d0), then
/// one reading d1 and writing d2; twice in a loop of 3 iterations when `loop`.
StepGraph dot_product(bool loop) {
  std::vector<std::vector<Access>> tasks;
  tasks.push_back({{0, AccessMode::W}});
  for (int i = 0; i < kWriters; ++i) tasks.push_back({{0, AccessMode::R}, {1, AccessMode::CW}});
  tasks.push_back({{1, AccessMode::R}, {2, AccessMode::RW}});
  StepGraph g = test::chain_graph(tasks, 3);
  if (loop) {
    Loop l;
    l.condition = 2;
    l.last = static_cast<TaskId>(g.tasks.size());
    l.iterations = 3;
    l.max_iterations = 3;
    g.loops.push_back(l);
    for (Task& t : g.tasks) t.loop = 0;
    g.derive_edges();
  }
  return g;
}

/// Bodies on doubles: CW writer i adds 1 / (i + 3) (inexact in binary, so the grouping of the
/// additions shows in the last bits) to the datum its access reaches on its thread; a
/// reducer adds the temporaries into the target; the reader copies d1 into d2 (RW: adds).
class DoubleSums final : public Workload {
 public:
  void bind(const ExecGraph& x) override { value_.assign(x.graph.data.size(), 0.0); }
  void run(const TaskRun& r) override {
    const ExecGraph& x = *r.exec;
    if (r.origin == kNoTask) {
      const Reduction& red = x.reductions[x.reduction[r.task]];
      for (DatumId t : red.temps) {
        value_[red.target] += value_[t];
        value_[t] = 0;
      }
      return;
    }
    for (const Access& a : x.graph.accesses_of(r.task)) {
      if (a.mode == AccessMode::CW)
        value_[x.datum_on(a.datum, r.thread)] += 1.0 / (r.origin + 3.0);
      else if (a.datum == 2)
        value_[2] += value_[1];
    }
  }
  bool stop_after(LoopId, std::uint32_t it) override { return it + 1 == 3; }
  double value(DatumId d) const { return value_[d]; }

 private:
  std::vector<double> value_;
};

ExecOptions per_thread(std::uint32_t k) {
  ExecOptions o;
  o.threads = k;
  o.pin = false;
  o.reduce_scope = ReduceScope::kPerThread;
  return o;
}

class PerThread : public ::testing::TestWithParam<Policy> {};

TEST_P(PerThread, MakesOneTemporaryPerThreadNotPerWriter) {
  const StepGraph g = dot_product(false);
  for (std::uint32_t k = 2; k <= 4; ++k) {
    auto ex = make_executor(GetParam(), per_thread(k));
    EXPECT_EQ(ex->scope(), ReduceScope::kPerThread);
    DoubleSums w;
    ex->run_step(g, nullptr, w);
    const ExecGraph& x = *ex->last_exec();
    ASSERT_EQ(x.reductions.size(), 1u);
    EXPECT_EQ(x.reductions[0].temps.size(), k);
    EXPECT_EQ(x.graph.data.size(), g.data.size() + k);  // not one per writer (39)
    EXPECT_EQ(x.thread_temps, k);
  }
}

TEST_P(PerThread, SumsEqualTheSequentialOnesWithinRounding) {
  for (bool loop : {false, true}) {
    const StepGraph g = dot_product(loop);
    ExecOptions so;
    so.reduce_scope = ReduceScope::kNone;
    auto seq = make_executor(Policy::kSequential, so);
    DoubleSums want;
    seq->run_step(g, nullptr, want);
    for (std::uint32_t k = 1; k <= 4; ++k) {
      auto ex = make_executor(GetParam(), per_thread(k));
      for (int step = 0; step < 3; ++step) {  // the plan and its temporaries are reused
        DoubleSums got;
        ex->run_step(g, nullptr, got);
        for (DatumId d : {DatumId{1}, DatumId{2}})
          EXPECT_NEAR(got.value(d), want.value(d), 1e-12 * std::abs(want.value(d)))
              << to_string(GetParam()) << " k=" << k << " loop=" << loop << " datum " << d;
      }
    }
  }
}

// The synthetic bodies' cumulative writes add exact integers: any grouping gives the
// sequential run's bits, data and temporaries alike.
TEST_P(PerThread, SyntheticBodiesEndWithTheSequentialBits) {
  for (std::uint32_t seed = 1; seed <= 6; ++seed) {
    const StepGraph g = test::random_graph(seed);
    for (std::uint32_t k = 2; k <= 4; k += 2) {
      auto ex = make_executor(GetParam(), per_thread(k));
      SyntheticWorkload w({.cost_scale = 0.0});
      w.set_step(g);
      ex->run_step(g, nullptr, w);
      EXPECT_EQ(test::final_state(w, g), test::sequential_state(g, 1))
          << to_string(GetParam()) << " seed " << seed << " k=" << k;
    }
  }
}

INSTANTIATE_TEST_SUITE_P(Policies, PerThread,
                         ::testing::Values(Policy::kWorksteal, Policy::kBarrier,
                                           Policy::kOmpTasks
#if defined(TGRAPH_HAVE_STARPU)
                                           ,
                                           Policy::kStarpu
#endif
                                           ),
                         [](const auto& p) {
                           std::string s(to_string(p.param));
                           std::erase(s, '-');
                           return s;
                         });

}  // namespace
}  // namespace tgraph::replay
