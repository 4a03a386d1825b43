// SPDX-License-Identifier: MIT
// tgraph::graph alone: a hand-built step, its edges and metrics, a trace written and read
// back, the version API.
#include <cstdio>
#include <filesystem>

#include "fork_join.hpp"
#include "tgraph/graph/metrics.hpp"
#include "tgraph/graph/trace_io.hpp"
#include "tgraph/version.hpp"

int main() {
  using consumer::expect;
  const tgraph::StepGraph g = consumer::fork_join();
  const tgraph::Metrics m = tgraph::compute_metrics(g);
  expect(m.tasks == consumer::kWidth + 1, "tasks");
  expect(m.edges == consumer::kWidth, "edges");
  for (const tgraph::Edge& e : g.edges) expect(e.kind == tgraph::EdgeKind::RAW, "edge kinds");
  expect(m.work_ns == (consumer::kWidth + 1) * consumer::kCostNs, "work");
  expect(m.span_ns == 2 * consumer::kCostNs, "span");

  const std::string path = (std::filesystem::temp_directory_path() / "consumer-graph.tgt").string();
  {
    tgraph::TraceWriter w(path, {"fork-join", "consumer", tgraph::machine_description(),
                                 std::string(tgraph::kVersionString)});
    w.append(g);
    w.append(g);
    w.close();
  }
  const tgraph::Trace t = tgraph::read_trace(path);
  std::filesystem::remove(path);
  expect(t.steps.size() == 2 && t.steps[1].edges == g.edges, "trace read back");

  expect(tgraph::linked_version() == tgraph::kVersionString, "header and library versions");
  expect(tgraph::kVersionString == TGRAPH_PACKAGE_VERSION, "version.hpp and the CMake package");
  expect(std::to_string(tgraph::kVersionMajor) + "." + std::to_string(tgraph::kVersionMinor) +
                 "." + std::to_string(tgraph::kVersionPatch) ==
             tgraph::kVersionString,
         "version numbers");
  std::printf("graph: %llu tasks, %llu edges, span %llu ns, tgraph %s\n",
              static_cast<unsigned long long>(m.tasks), static_cast<unsigned long long>(m.edges),
              static_cast<unsigned long long>(m.span_ns), tgraph::kVersionString.data());
  return 0;
}
