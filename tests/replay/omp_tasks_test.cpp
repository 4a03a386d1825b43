// SPDX-License-Identifier: MIT
// The omp-tasks policy beyond what every policy is tested for (executor_test, fairness_test):
// CW groups declared mutexinoutset, loops decided by the submitting thread, no taskwait,
// taskwait depend on the break task.
#include <gtest/gtest.h>

#include <cstdlib>
#include <optional>
#include <stdexcept>
#include <string>

#include "random_graph.hpp"
#include "tgraph/graph/error.hpp"
#include "tgraph/replay/executor.hpp"
#include "tgraph/replay/synthetic.hpp"

namespace tgraph::replay {
namespace {

/// The synthetic bodies with the loop counts hidden, as in a live run: the executor must
/// submit one iteration at a time and wait for the break task's decision. `throw_at`: the
/// loop condition throws after that iteration of loop 0.
class LiveLikeWorkload : public SyntheticWorkload {
 public:
  explicit LiveLikeWorkload(std::optional<std::uint32_t> throw_at = std::nullopt)
      : SyntheticWorkload({.cost_scale = 0.0}), throw_at_(throw_at) {}
  std::optional<std::uint32_t> known_iterations(LoopId) const override { return std::nullopt; }
  bool stop_after(LoopId loop, std::uint32_t iteration) override {
    if (loop == 0 && throw_at_ == iteration) throw std::runtime_error("condition failed");
    return SyntheticWorkload::stop_after(loop, iteration);
  }

 private:
  std::optional<std::uint32_t> throw_at_;
};

ExecOptions omp_options(std::uint32_t k) {
  ExecOptions o;
  o.threads = k;
  return o;
}

/// Runs `steps` steps of g under omp-tasks with `o` and returns the final state.
std::vector<std::vector<std::uint64_t>> omp_state(const StepGraph& g, const ExecOptions& o,
                                                  SyntheticWorkload& w, int steps) {
  auto ex = make_executor(Policy::kOmpTasks, o);
  w.set_step(g);
  for (int s = 0; s < steps; ++s) {
    const ExecStepStats st = ex->run_step(g, nullptr, w);
    for (LoopId l = 0; l < g.loops.size(); ++l)
      EXPECT_EQ(st.loop_iterations[l], g.loops[l].iterations) << "loop " << l;
  }
  return test::final_state(w, g);
}

TEST(OmpTasks, MutexinoutsetGroupsReachTheSequentialStateWithoutReducers) {
  for (std::uint32_t seed = 1; seed <= 4; ++seed)
    for (std::uint32_t k : {2u, 3u}) {
      const StepGraph g = test::random_graph(seed * 31 + k);
      ExecOptions o = omp_options(k);
      o.reduce_scope = ReduceScope::kNone;  // CW groups stay whole: mutexinoutset
      auto ex = make_executor(Policy::kOmpTasks, o);
      SyntheticWorkload w({.cost_scale = 0.0});
      w.set_step(g);
      ex->run_step(g, nullptr, w);
      ex->run_step(g, nullptr, w);
      EXPECT_TRUE(ex->last_exec()->reductions.empty());
      EXPECT_EQ(test::final_state(w, g), test::sequential_state(g, 2))
          << "seed " << seed << " k " << k;
    }
}

TEST(OmpTasks, WithoutATaskwaitPerIterationTheUnrolledStepStillMatches) {
  for (std::uint32_t seed = 1; seed <= 4; ++seed) {
    const StepGraph g = test::random_graph(seed * 17);
    ExecOptions o = omp_options(2);
    o.omp_tasks.iteration_wait = false;
    SyntheticWorkload w({.cost_scale = 0.0});
    EXPECT_EQ(omp_state(g, o, w, 2), test::sequential_state(g, 2)) << "seed " << seed;
  }
}

TEST(OmpTasks, SaysWhichOpenMPRuntimeRuns) {
  // The runtime the build links (clang's -fopenmp: LLVM's libomp; GCC's: libgomp) unless the
  // ctest that preloads LLVM's libomp says otherwise (tests/replay).
  const char* want = std::getenv("TGRAPH_EXPECT_OPENMP_RUNTIME");
#if defined(__clang__)
  const std::string linked = "llvm";
#else
  const std::string linked = "gnu";
#endif
  EXPECT_EQ(openmp_runtime(), want != nullptr ? std::string(want) : linked);
}

TEST(OmpTasks, WaitingForTheBreakTaskOnlyStillMatches) {
  // taskwait depend(in:) on the break task: unrolled (replay) and host-decided (live) loops.
  // The executor refuses it on LLVM's runtime (libomp 14 aborts on it), which a clang build
  // links.
  if (openmp_runtime() == "llvm") GTEST_SKIP() << "taskwait depend is refused on LLVM's runtime";
  for (std::uint32_t seed = 1; seed <= 4; ++seed)
    for (std::uint32_t k : {2u, 3u}) {
      const StepGraph g = test::random_graph(seed * 23 + k);
      ExecOptions o = omp_options(k);
      o.omp_tasks.wait_depend = true;
      SyntheticWorkload known({.cost_scale = 0.0});
      EXPECT_EQ(omp_state(g, o, known, 2), test::sequential_state(g, 2)) << "seed " << seed;
      LiveLikeWorkload live;
      EXPECT_EQ(omp_state(g, o, live, 2), test::sequential_state(g, 2)) << "seed " << seed;
    }
}

TEST(OmpTasks, LoopsWithoutAKnownCountAreDecidedIterationByIteration) {
  for (std::uint32_t seed = 1; seed <= 4; ++seed)
    for (std::uint32_t k : {1u, 2u, 4u}) {
      const StepGraph g = test::random_graph(seed * 13 + k);
      LiveLikeWorkload w;
      EXPECT_EQ(omp_state(g, omp_options(k), w, 2), test::sequential_state(g, 2))
          << "seed " << seed << " k " << k;
    }
}

TEST(OmpTasks, RethrowsALoopConditionExceptionAndStaysUsable) {
  const StepGraph g = test::random_graph(42);
  ASSERT_FALSE(g.loops.empty());
  auto ex = make_executor(Policy::kOmpTasks, omp_options(2));
  LiveLikeWorkload bad(0);
  bad.set_step(g);
  try {
    ex->run_step(g, nullptr, bad);
    ADD_FAILURE() << "no exception";
  } catch (const std::runtime_error& e) {
    EXPECT_EQ(std::string(e.what()), "condition failed");
  }
  LiveLikeWorkload ok;
  ok.set_step(g);
  const ExecStepStats s = ex->run_step(g, nullptr, ok);
  EXPECT_EQ(s.loop_iterations[0], g.loops[0].iterations);
}

TEST(OmpTasks, RejectsAKnownCountTheConditionContradicts) {
  // The condition stops after the first iteration while known_iterations says more.
  class Lying : public SyntheticWorkload {
   public:
    Lying() : SyntheticWorkload({.cost_scale = 0.0}) {}
    bool stop_after(LoopId, std::uint32_t) override { return true; }
  };
  const StepGraph g = test::random_graph(7);
  ASSERT_GT(g.loops[0].iterations, 1u);
  auto ex = make_executor(Policy::kOmpTasks, omp_options(2));
  Lying w;
  w.set_step(g);
  EXPECT_THROW(ex->run_step(g, nullptr, w), UsageError);
}

}  // namespace
}  // namespace tgraph::replay
