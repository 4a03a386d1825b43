// SPDX-License-Identifier: MIT
// tgraph::measure: the fork-join step replayed under the partition policy against sequential
// (two timed passes), and a built-in scene captured in memory.
#include <cstdio>
#include <nlohmann/json.hpp>

#include "fork_join.hpp"
#include "tgraph/measure/capture.hpp"
#include "tgraph/measure/replay_trace.hpp"
#include "tgraph/measure/report.hpp"

int main() {
  using consumer::expect;
  tgraph::Trace trace;
  trace.steps = {consumer::fork_join(), consumer::fork_join()};
  tgraph::TraceAssignment as;
  as.k = 2;
  for (const tgraph::StepGraph& g : trace.steps) {
    tgraph::Assignment a;
    a.k = 2;
    for (tgraph::TaskId t = 0; t < g.tasks.size(); ++t) a.proc.push_back(t % 2);
    as.steps.push_back(a);
  }
  tgraph::measure::ReplayOptions o;
  o.exec.threads = 2;
  o.exec.pin = false;
  o.repeat = 2;
  o.synthetic.touch = false;
  const tgraph::measure::ReplayResult r = tgraph::measure::replay_trace(trace, &as, o);
  expect(r.steps.size() == 2 && r.pass_wall_ns.size() == 2 && r.sequential_pass_wall_ns.size() == 2,
         "two steps, two timed passes of each");
  expect(r.wall_ns > 0 && r.sequential_wall_ns > 0 && r.speedup > 0, "timed against sequential");
  expect(r.work_ns == 2 * (consumer::kWidth + 1) * consumer::kCostNs, "work of both steps");
  const auto j = nlohmann::json::parse(tgraph::measure::to_json(r));
  expect(j["per_step"].size() == 2 && j.contains("speedup"), "JSON per step");

  const tgraph::Trace fig2 = tgraph::measure::capture_trace("fig2", 2);
  expect(fig2.steps.size() == 2 && !fig2.steps[0].tasks.empty(), "fig2 captured in memory");
  std::printf("measure consumer: replay speed-up %.2f, fig2 step 0 has %zu tasks\n", r.speedup,
              fig2.steps[0].tasks.size());
  return 0;
}
