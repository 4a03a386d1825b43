// SPDX-License-Identifier: MIT
// tgraph::capture (configured without oneTBB): tasks without objects recorded as they run.
#include <cstdio>

#include "fork_join.hpp"
#include "tgraph/capture/recorder.hpp"

int main() {
  using consumer::expect;
  using tgraph::AccessMode;
  tgraph::capture::Recorder rec{tgraph::capture::Mode::kCapture};
  std::vector<double> x(consumer::kWidth, 1.0);
  double total = 0;
  std::vector<tgraph::DatumId> xi;
  for (std::uint32_t i = 0; i < consumer::kWidth; ++i)
    xi.push_back(rec.datum("x" + std::to_string(i), tgraph::kNoObject, sizeof(double), &x[i]));
  const tgraph::DatumId t = rec.datum("total", tgraph::kNoObject, sizeof(double), &total);
  const tgraph::KindId scale = rec.kind("scale"), sum = rec.kind("sum");
  rec.begin_step();
  for (std::uint32_t i = 0; i < consumer::kWidth; ++i)
    rec.task(scale, tgraph::kNoObject, {{xi[i], AccessMode::RW}}, [&x, i] { x[i] *= i + 1; });
  std::vector<tgraph::Access> all;
  for (tgraph::DatumId d : xi) all.push_back({d, AccessMode::R});
  all.push_back({t, AccessMode::W});
  rec.task(sum, tgraph::kNoObject, all, [&] {
    for (double v : x) total += v;
  });
  const tgraph::StepGraph g = rec.end_step();

  expect(rec.errors() == 0, "recorder errors");
  expect(total == consumer::kWidth * (consumer::kWidth + 1) / 2, "the bodies ran, in order");
  const tgraph::StepGraph expected = consumer::fork_join();
  expect(g.tasks.size() == expected.tasks.size(), "tasks");
  expect(g.edges.size() == expected.edges.size(), "edges");
  for (std::size_t e = 0; e < g.edges.size(); ++e)
    expect(g.edges[e].from == expected.edges[e].from && g.edges[e].to == expected.edges[e].to &&
               g.edges[e].kind == expected.edges[e].kind,
           "edge " + std::to_string(e));
  std::printf("capture: %zu tasks, %zu edges, total %.0f\n", g.tasks.size(), g.edges.size(), total);
  return 0;
}
