// SPDX-License-Identifier: MIT
// Explanations of timelines recorded on real threads: whatever the timing, the causes add
// up to the lost time, the residual is small and the critical path spans the makespan.
#include <gtest/gtest.h>

#include <string>

#include "tgraph/explain/explain.hpp"
#include "tgraph/graph/generate.hpp"
#include "tgraph/replay/executor.hpp"
#include "tgraph/replay/observer.hpp"
#include "tgraph/replay/synthetic.hpp"

namespace tgraph::explain {
namespace {

class Replayed : public ::testing::TestWithParam<replay::Policy> {};

TEST_P(Replayed, CausesAddUpToTheLostTime) {
  GenerateOptions go;
  go.pattern = Pattern::kDomain;
  go.tasks = 120;
  go.iterations = 4;
  go.cost_ns = 2000;
  replay::ExecOptions o;
  o.threads = 2;
  o.pin = false;
  auto ex = replay::make_executor(GetParam(), o);
  replay::TimelineObserver timeline;
  ex->add_observer(timeline);
  replay::SyntheticWorkload w;
  for (std::uint32_t step = 0; step < 2; ++step) {
    StepGraph g = generate_step(go, step);
    g.derive_edges();
    Assignment a;
    a.k = 2;
    for (TaskId t = 0; t < g.tasks.size(); ++t) a.proc.push_back(g.tasks[t].object % 2);
    w.set_step(g);
    ex->run_step(g, GetParam() == replay::Policy::kPartition ? &a : nullptr, w);
  }
  const Timeline t = parse_timeline(timeline_json(timeline.timeline()), "r.json");
  ASSERT_EQ(t.step_info.size(), 2u);
  EXPECT_EQ(t.graphs.size(), 1u);  // one structure, one graph
  const Explanation e = explain_timeline(t, "r.json");
  ASSERT_EQ(e.steps.size(), 2u);
  for (const StepExplanation& s : e.steps) {
    EXPECT_EQ(s.unobserved, 0u);
    EXPECT_EQ(s.attribution.causes.sum(), s.attribution.lost_ns) << "step " << s.step;
    EXPECT_LE(std::abs(s.attribution.causes.residual), s.threads * s.makespan_ns / 20)
        << "step " << s.step;
    std::int64_t along = 0;
    for (const auto& [name, ns] : s.makespan_split) along += ns;
    EXPECT_EQ(along, s.makespan_ns) << "step " << s.step;
    ASSERT_FALSE(s.critical_path.empty());
    EXPECT_EQ(s.critical_path.back().end_ns, s.makespan_ns);
    for (std::size_t k = 1; k < s.critical_path.size(); ++k)
      EXPECT_EQ(s.critical_path[k].start_ns, s.critical_path[k - 1].end_ns) << "link " << k;
  }
}

INSTANTIATE_TEST_SUITE_P(Policies, Replayed,
                         ::testing::Values(replay::Policy::kPartition, replay::Policy::kWorksteal,
                                           replay::Policy::kBarrier),
                         [](const auto& p) { return std::string(to_string(p.param)); });

}  // namespace
}  // namespace tgraph::explain
