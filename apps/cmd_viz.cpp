// SPDX-License-Identifier: MIT
// `tgraph viz`: one step's graph through Graphviz (DOT, SVG, PNG, PDF): viz::trace_step_view.
#include <cstdio>

#include "commands.hpp"
#include "tgraph/partition/assignment_io.hpp"
#include "tgraph/viz/graphviz.hpp"

namespace tgraph::app {

void add_viz_verbs(CLI::App& app) {
  auto a = std::make_shared<Args>();
  auto o = std::make_shared<viz::ViewOptions>();
  auto* cmd = app.add_subcommand(
      "viz", "Draw one step's dataflow graph (DOT, SVG, PNG or PDF by extension)");
  cmd->add_option("trace", a->input, "Trace file (.tgt)")->required();
  cmd->add_option("--step", a->step, "Step index (0-based; default 0)");
  cmd->add_option("--assign", a->assignment,
                  "Assignment (.tga): colours by processor, signal/wait/reducer nodes");
  cmd->add_option("--collapse", a->collapse, "none (default), object, kind, processor or loop");
  cmd->add_flag("--critical-path", o->critical_path,
                "Highlight the critical path (loops unrolled)");
  cmd->add_option("--max-nodes", o->max_nodes,
                  "Refuse pictures with more nodes (default 2000; 0: no limit)");
  cmd->add_option("--max-edges", o->max_edges,
                  "Refuse pictures with more edges (default 4000; 0: no limit)");
  cmd->add_option("-o,--output", a->output, "Output file: .dot, .svg, .png or .pdf")->required();
  cmd->callback([a, o] {
    const viz::GraphFormat format = viz::graph_format_of(a->output);
    o->collapse = viz::parse_collapse(a->collapse);
    const Trace trace = read_trace(a->input);
    step_at(trace, a->step, a->input);  // before the assignment is checked against the trace
    std::optional<TraceAssignment> as;
    if (!a->assignment.empty()) as = partition::load_assignment(a->assignment, trace, a->input);
    const viz::GraphView v =
        viz::trace_step_view(trace, a->input, a->step, as ? &*as : nullptr, *o);
    write_file_atomic(a->output, viz::render_graph(v, format));
    if (v.collapse != viz::Collapse::kNone && v.hidden_deps > 0)
      std::fprintf(stderr, "tgraph viz: %s\n", viz::hidden_deps_note(v).c_str());
  });
  add_timeline(app);
  add_report(app);
}

}  // namespace tgraph::app
