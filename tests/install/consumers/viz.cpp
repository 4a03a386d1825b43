// SPDX-License-Identifier: MIT
// tgraph::viz: the step's picture through Graphviz's libraries, as SVG.
#include <cstdio>
#include <string>

#include "fork_join.hpp"
#include "tgraph/viz/graph_view.hpp"
#include "tgraph/viz/graphviz.hpp"

int main() {
  using consumer::expect;
  const tgraph::StepGraph g = consumer::fork_join();
  const tgraph::viz::GraphView view = tgraph::viz::make_graph_view(g, {});
  expect(view.nodes.size() == consumer::kWidth + 1, "nodes");
  expect(view.edges.size() == consumer::kWidth, "edges");
  const std::string svg = tgraph::viz::render_graph(view, tgraph::viz::GraphFormat::kSvg);
  std::size_t nodes = 0, edges = 0;
  for (std::uint32_t t = 0; t < g.tasks.size(); ++t)  // a node per task, titled t<id>
    if (svg.find("<title>t" + std::to_string(t) + "</title>") != std::string::npos) ++nodes;
  for (std::size_t at = 0; (at = svg.find("class=\"edge\"", at)) != std::string::npos; ++at) ++edges;
  expect(svg.find("<svg") != std::string::npos, "an SVG document");
  expect(nodes == consumer::kWidth + 1 && edges == consumer::kWidth, "drawn nodes and edges");
  std::printf("viz: SVG of %zu bytes, %zu nodes, %zu edges\n", svg.size(), nodes, edges);
  return 0;
}
