// SPDX-License-Identifier: MIT
// The StarPU policy: same results as the sequential run, dataflow order, loops unrolled or
// synchronised on the host, exceptions, observers, one runtime per process.
#include <gtest/gtest.h>

#include <map>
#include <optional>
#include <stdexcept>
#include <string>
#include <vector>

#include "random_graph.hpp"
#include "tgraph/graph/error.hpp"
#include "tgraph/replay/executor.hpp"
#include "tgraph/replay/synthetic.hpp"

namespace tgraph::replay {
namespace {

using test::final_state;
using test::sequential_state;

#if !defined(TGRAPH_HAVE_STARPU)
#define TGRAPH_NEED_STARPU() GTEST_SKIP() << "tgraph was built without StarPU"
#else
#define TGRAPH_NEED_STARPU() (void)0
#endif

/// How CW groups reach StarPU.
enum class Cw { kPerWriter, kCommute, kSerialize };

std::string cw_name(Cw c) {
  switch (c) {
    case Cw::kPerWriter:
      return "per_writer";
    case Cw::kCommute:
      return "commute";
    case Cw::kSerialize:
      return "serialize";
  }
  return "?";
}

/// Per-writer temporaries (the default), CW left to STARPU_COMMUTE, or CW made RW.
ExecOptions starpu_options(std::uint32_t k, Cw cw = Cw::kPerWriter) {
  ExecOptions o;
  o.threads = k;
  if (cw == Cw::kCommute) o.reduce_scope = ReduceScope::kNone;
  if (cw == Cw::kSerialize) o.cw = CwMode::kSerialize;
  return o;
}

/// Synthetic bodies whose loop counts are only known when the break task decides (as in a
/// live run): the executor must synchronise on the host once per iteration.
class UnknownCounts : public SyntheticWorkload {
 public:
  using SyntheticWorkload::SyntheticWorkload;
  std::optional<std::uint32_t> known_iterations(LoopId) const override { return std::nullopt; }
};

class StarpuPolicy
    : public ::testing::TestWithParam<std::tuple<std::uint32_t, Cw, bool /*unknown*/>> {};

TEST_P(StarpuPolicy, RunsEachTaskAfterItsPredecessorsAndMatchesSequentialState) {
  TGRAPH_NEED_STARPU();
  const auto [k, cw, unknown] = GetParam();
  auto ex = make_executor(Policy::kStarpu, starpu_options(k, cw));
  TimelineObserver timeline;
  StatsObserver stats;
  ex->add_observer(timeline);
  ex->add_observer(stats);
  for (std::uint32_t seed = 1; seed <= 6; ++seed) {
    const StepGraph g = test::random_graph(seed * 7919 + k);
    std::unique_ptr<SyntheticWorkload> w =
        unknown ? std::make_unique<UnknownCounts>(SyntheticOptions{.cost_scale = 0.2})
                : std::make_unique<SyntheticWorkload>(SyntheticOptions{.cost_scale = 0.2});
    w->set_step(g);
    const std::uint64_t built = ex->plans_built();
    for (int step = 0; step < 2; ++step) {
      const ExecStepStats s = ex->run_step(g, nullptr, *w);
      EXPECT_EQ(s.rebuilt, step == 0);
      ASSERT_EQ(s.loop_iterations.size(), g.loops.size());
      for (LoopId l = 0; l < g.loops.size(); ++l)
        EXPECT_EQ(s.loop_iterations[l], g.loops[l].iterations);
      ASSERT_NE(ex->last_exec(), nullptr);
      const StepGraph& xg = ex->last_exec()->graph;
      std::uint64_t instances = 0, counted = 0, observed = 0;
      for (TaskId t = 0; t < xg.tasks.size(); ++t) instances += xg.runs(t);
      for (const ThreadCounters& c : s.threads) counted += c.tasks;
      for (const StatsObserver::Thread& t : stats.threads()) observed += t.tasks;
      EXPECT_EQ(s.threads.size(), k);
      EXPECT_EQ(counted, instances);
      EXPECT_EQ(observed, instances);
      const auto step_index = static_cast<std::uint32_t>(timeline.timeline().tasks.back().step);
      // Unlike the other policies, an unrolled loop has no gate: iteration i + 1 may start
      // before the break of iteration i.
      test::expect_valid_order(xg, timeline.timeline().tasks, step_index,
                               {.exec = true, .loop_gate = false});
    }
    EXPECT_EQ(ex->plans_built(), built + 1);
    const auto got = final_state(*w, g), want = sequential_state(g, 2);
    for (DatumId d = 0; d < g.data.size(); ++d)
      EXPECT_TRUE(got[d] == want[d]) << "seed " << seed << " k " << k << ": datum "
                                     << g.data[d].name << " differs from the sequential run";
    if (::testing::Test::HasFailure()) return;
  }
}

INSTANTIATE_TEST_SUITE_P(Threads1To4, StarpuPolicy,
                         ::testing::Combine(::testing::Range(1u, 5u),
                                            ::testing::Values(Cw::kPerWriter, Cw::kCommute,
                                                              Cw::kSerialize),
                                            ::testing::Bool()),
                         [](const auto& param_info) {
                           return "k" + std::to_string(std::get<0>(param_info.param)) + "_" +
                                  cw_name(std::get<1>(param_info.param)) +
                                  (std::get<2>(param_info.param) ? "_host_sync" : "_unrolled");
                         });

/// Ten CW writers of one datum, each also reading 10 private data (11 handles: more than
/// StarPU's 8 static buffers), then a reader.
TEST(Starpu, CommutingWritersWithManyHandlesMatchSequential) {
  TGRAPH_NEED_STARPU();
  StepGraph g;
  g.intern_kind("add");
  g.intern_kind("read");
  g.data.push_back({"sum", kNoObject, 256});
  g.data.push_back({"out", kNoObject, 256});
  for (int i = 0; i < 10; ++i) g.data.push_back({"in" + std::to_string(i), kNoObject, 64});
  for (int w = 0; w < 10; ++w) {
    std::vector<Access> acc{{0, AccessMode::CW}};
    for (DatumId d = 2; d < 12; ++d) acc.push_back({d, AccessMode::R});
    g.add_task(0, kNoObject, acc, 2000, static_cast<StableKey>(w + 1));
  }
  const Access rd[] = {{0, AccessMode::R}, {1, AccessMode::W}};
  g.add_task(1, kNoObject, rd, 100, 99);
  g.derive_edges();
  for (Cw cw : {Cw::kPerWriter, Cw::kCommute}) {
    auto ex = make_executor(Policy::kStarpu, starpu_options(2, cw));
    TimelineObserver timeline;
    ex->add_observer(timeline);
    SyntheticWorkload w({.cost_scale = 1.0});
    w.set_step(g);
    ex->run_step(g, nullptr, w);
    ex->run_step(g, nullptr, w);
    EXPECT_EQ(final_state(w, g), sequential_state(g, 2)) << cw_name(cw);
    test::expect_valid_order(ex->last_exec()->graph, timeline.timeline().tasks, 1,
                             {.exec = true, .loop_gate = false});
  }
}

using test::Throwing;

TEST(Starpu, RethrowsATaskExceptionAfterWaitingAndStaysUsable) {
  TGRAPH_NEED_STARPU();
  const StepGraph g = test::random_graph(42);
  for (std::uint32_t k : {1u, 2u, 4u}) {
    auto ex = make_executor(Policy::kStarpu, starpu_options(k));
    for (std::optional<std::uint32_t> known :
         {std::optional<std::uint32_t>{}, std::optional<std::uint32_t>{2}}) {
      for (TaskId bad : {TaskId{0}, static_cast<TaskId>(g.tasks.size() / 2), g.loops[0].last - 2}) {
        Throwing w(bad);
        w.set_known(known);
        try {
          ex->run_step(g, nullptr, w);
          ADD_FAILURE() << "k=" << k << ": no exception";
        } catch (const std::runtime_error& e) {
          EXPECT_EQ(std::string(e.what()), "task " + std::to_string(bad) + " failed");
        }
      }
    }
    SyntheticWorkload ok({.cost_scale = 0.0});
    ok.set_step(g);
    EXPECT_NO_THROW(ex->run_step(g, nullptr, ok)) << "k=" << k;
  }
}

TEST(Starpu, RejectsKnownIterationsThatContradictTheCondition) {
  TGRAPH_NEED_STARPU();
  StepGraph g = test::random_graph(7);
  for (Loop& l : g.loops) l.max_iterations = 0;  // the condition alone decides
  auto ex = make_executor(Policy::kStarpu, starpu_options(2));
  Throwing w(1'000'000);  // throws nowhere; stops after iteration 1, i.e. 2 iterations
  w.set_known(3);
  EXPECT_THROW(ex->run_step(g, nullptr, w), UsageError);
  w.set_known(2);
  const ExecStepStats s = ex->run_step(g, nullptr, w);
  for (std::uint32_t it : s.loop_iterations) EXPECT_EQ(it, 2u);
}

TEST(Starpu, AllowsOneRuntimePerProcessAndChecksItsOptions) {
  TGRAPH_NEED_STARPU();
  {
    auto first = make_executor(Policy::kStarpu, starpu_options(1));
    try {
      auto second = make_executor(Policy::kStarpu, starpu_options(1));
      FAIL() << "a second StarPU executor was created";
    } catch (const UsageError& e) {
      EXPECT_NE(std::string(e.what()).find("another StarPU executor"), std::string::npos)
          << e.what();
    }
  }
  EXPECT_NO_THROW(make_executor(Policy::kStarpu, starpu_options(1)));  // the first is gone
  ExecOptions bad = starpu_options(2);
  bad.starpu.sched = "no-such-scheduler";
  try {
    make_executor(Policy::kStarpu, bad);
    FAIL() << "unknown scheduler accepted";
  } catch (const UsageError& e) {
    EXPECT_NE(std::string(e.what()).find("lws"), std::string::npos) << e.what();
  }
  EXPECT_THROW(make_executor(Policy::kStarpu, starpu_options(64)), UsageError);
  for (const char* sched : {"eager", "ws", "prio"}) {
    ExecOptions o = starpu_options(2);
    o.starpu.sched = sched;
    auto ex = make_executor(Policy::kStarpu, o);
    const StepGraph g = test::random_graph(3);
    SyntheticWorkload w({.cost_scale = 0.0});
    w.set_step(g);
    ex->run_step(g, nullptr, w);
    EXPECT_EQ(final_state(w, g), sequential_state(g, 1)) << sched;
  }
}

#if !defined(TGRAPH_HAVE_STARPU)
TEST(Starpu, SaysItIsMissingWhenBuiltWithout) {
  try {
    make_executor(Policy::kStarpu, starpu_options(2));
    FAIL() << "no error";
  } catch (const UsageError& e) {
    EXPECT_NE(std::string(e.what()).find("built without StarPU"), std::string::npos);
  }
}
#endif

}  // namespace
}  // namespace tgraph::replay
