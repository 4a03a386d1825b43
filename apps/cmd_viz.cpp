// SPDX-License-Identifier: MIT
// `tgraph viz`: one step's graph through Graphviz (DOT, SVG, PNG, PDF).
#include <filesystem>

#include "commands.hpp"
#include "tgraph/graph/file_util.hpp"
#include "tgraph/partition/assignment_io.hpp"
#include "tgraph/viz/graphviz.hpp"

namespace tgraph::app {
namespace {

struct VizCmd {
  std::string trace, assignment, out, collapse = "none";
  std::size_t step = 0;
  std::size_t max_nodes = 2000, max_edges = 4000;
  bool critical_path = false;
};

void run_viz(const VizCmd& c) {
  const viz::GraphFormat format = viz::graph_format_of(c.out);
  const viz::Collapse collapse = viz::parse_collapse(c.collapse);
  const Trace trace = load_trace(c.trace);
  if (c.step >= trace.steps.size())
    throw UsageError("--step " + std::to_string(c.step) + ": trace " + c.trace + " has " +
                     std::to_string(trace.steps.size()) + " steps");
  TraceAssignment assignment;
  viz::ViewOptions o;
  o.collapse = collapse;
  o.critical_path = c.critical_path;
  o.max_nodes = c.max_nodes;
  o.max_edges = c.max_edges;
  o.title = std::filesystem::path(c.trace).filename().string() + ", step " + std::to_string(c.step);
  if (!c.assignment.empty()) {
    assignment = partition::load_assignment(c.assignment, trace, c.trace);
    o.assignment = &assignment.steps[c.step];
    o.title += ", " + assignment.method + " on " + std::to_string(assignment.k) + " processors";
  }
  viz::GraphView view;
  try {
    view = viz::make_graph_view(trace.steps[c.step], o);
  } catch (const UsageError& e) {
    throw UsageError(c.trace + ": step " + std::to_string(c.step) + ": " + e.what());
  }
  write_file_atomic(c.out, viz::render_graph(view, format));
}

}  // namespace

void add_viz_verbs(CLI::App& app) {
  auto c = std::make_shared<VizCmd>();
  auto* cmd = app.add_subcommand("viz", "Draw one step's dataflow graph (DOT, SVG, PNG or PDF by extension)");
  cmd->add_option("trace", c->trace, "Trace file (.tgt)")->required();
  cmd->add_option("--step", c->step, "Step index (0-based; default 0)");
  cmd->add_option("--assign", c->assignment, "Assignment (.tga): colours by processor, signal/wait/reducer nodes");
  cmd->add_option("--collapse", c->collapse, "none (default), object, kind, processor or loop");
  cmd->add_flag("--critical-path", c->critical_path, "Highlight the critical path (loops unrolled)");
  cmd->add_option("--max-nodes", c->max_nodes, "Refuse pictures with more nodes (default 2000; 0: no limit)");
  cmd->add_option("--max-edges", c->max_edges, "Refuse pictures with more edges (default 4000; 0: no limit)");
  cmd->add_option("-o,--output", c->out, "Output file: .dot, .svg, .png or .pdf")->required();
  cmd->callback([c] { run_viz(*c); });
  add_timeline(app);
  add_report(app);
}

}  // namespace tgraph::app
