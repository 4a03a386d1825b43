// SPDX-License-Identifier: MIT
// The drawing verbs: `tgraph viz` (a step's graph: viz::trace_step_view), `tgraph timeline`
// (a Gantt chart) and `tgraph report` (HTML: viz::report_from_files, partition::step_quotient).
#include <cstdio>

#include "commands.hpp"
#include "tgraph/partition/assignment_io.hpp"
#include "tgraph/partition/evaluate.hpp"
#include "tgraph/viz/graphviz.hpp"
#include "tgraph/viz/report.hpp"
#include "tgraph/viz/timeline.hpp"

namespace tgraph::app {
namespace {

/// The assignment file `a.assignment` checked against `trace`; nullopt when none is given.
std::optional<TraceAssignment> assignment_of(const Args& a, const Trace& trace) {
  if (a.assignment.empty()) return std::nullopt;
  return partition::load_assignment(a.assignment, trace, a.input);
}

}  // namespace

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
    const std::optional<TraceAssignment> as = assignment_of(*a, trace);
    const viz::GraphView v =
        viz::trace_step_view(trace, a->input, a->step, as ? &*as : nullptr, *o);
    write_file_atomic(a->output, viz::render_graph(v, format));
    if (v.collapse != viz::Collapse::kNone && v.hidden_deps > 0)
      std::fprintf(stderr, "tgraph viz: %s\n", viz::hidden_deps_note(v).c_str());
  });
  add_timeline(app);
  add_report(app);
}

void add_timeline(CLI::App& app) {
  auto a = std::make_shared<Args>();
  auto* cmd = app.add_subcommand(
      "timeline", "Draw a replay timeline (tgraph replay --timeline) as a Gantt chart");
  cmd->add_option("timeline", a->input, "Timeline file (JSON from tgraph replay --timeline)")
      ->required();
  cmd->add_option("--steps", a->range, "Step range a:b, a: or a (default: all)");
  cmd->add_option("-o,--output", a->output, "Output file: .svg or .png")->required();
  cmd->callback([a] {
    const viz::TimelineFormat format = viz::timeline_format_of(a->output);
    Timeline t = read_timeline(a->input);
    if (!a->range.empty()) {
      const auto r = viz::parse_step_range(a->range);
      if (!r) throw UsageError("--steps " + a->range + ": expected a:b, a: or a (steps, a <= b)");
      t = viz::select_steps(t, r->first, r->second);
    }
    write_file_atomic(a->output, viz::render_timeline(t, format, viz::timeline_title(t, a->input)));
  });
}

void add_report(CLI::App& app) {
  auto a = std::make_shared<Args>();
  a->step = 1;
  auto* cmd = app.add_subcommand(
      "report", "Write a self-contained HTML report (tables, charts, timeline, graph)");
  cmd->add_option("trace", a->input, "Trace file (.tgt)")->required();
  cmd->add_option("--replay", a->names,
                  "Replay timelines (replay --timeline) or measurements (replay --json)");
  cmd->add_option("--compare", a->compare, "Method x K comparison (tgraph compare --json)");
  cmd->add_option("--assign", a->assignment, "Assignment (.tga) colouring the step graph");
  cmd->add_option("--step", a->step, "Step drawn as a graph (default 1, or 0 for one-step traces)");
  cmd->add_option("-o,--output", a->output, "Output file (.html)")->required();
  cmd->callback([a] {
    const Trace trace = read_trace(a->input);
    const std::optional<TraceAssignment> as = assignment_of(*a, trace);
    viz::ReportContent c =
        viz::report_from_files(trace, a->input, as ? &*as : nullptr, a->step, a->compare, a->names);
    if (as && !c.graph_svg.empty())
      viz::set_quotient(
          c, partition::step_quotient(trace.steps[c.graph_step], as->steps[c.graph_step]),
          as->method);
    write_file_atomic(a->output, viz::report_html(c));
    std::printf("report: %s\n", a->output.c_str());
  });
}

}  // namespace tgraph::app
