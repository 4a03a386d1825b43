// SPDX-License-Identifier: MIT
// The drawing verbs: `tgraph viz` (a step's graph: viz::draw_step), `tgraph timeline` (a Gantt
// chart: viz::draw_timeline) and `tgraph report` (HTML: viz::write_report).
#include <cstdio>

#include "commands.hpp"
#include "option_words.hpp"
#include "tgraph/partition/assignment_io.hpp"
#include "tgraph/partition/evaluate.hpp"
#include "tgraph/viz/graphviz.hpp"
#include "tgraph/viz/report.hpp"
#include "tgraph/viz/timeline.hpp"

namespace tgraph::app {

void add_viz_verbs(CLI::App& app) {
  using enum viz::Collapse;
  auto a = std::make_shared<Args>();
  auto o = std::make_shared<viz::ViewOptions>();
  auto* cmd = app.add_subcommand(
      "viz", "Draw one step's dataflow graph (DOT, SVG, PNG or PDF by extension)");
  cmd->add_option("trace", a->input, "Trace file (.tgt)")->required();
  cmd->add_option("--step", a->step, "Step index (0-based; default 0)");
  cmd->add_option("--assign", a->assignment,
                  "Assignment (.tga): colours by processor, signal/wait/reducer nodes");
  add_enum(cmd, "--collapse", o->collapse, {kNone, kObject, kKind, kProcessor, kLoop},
           "none (default), object, kind, processor or loop");
  cmd->add_flag("--critical-path", o->critical_path,
                "Highlight the critical path (loops unrolled)");
  cmd->add_option("--max-nodes", o->max_nodes,
                  "Refuse pictures with more nodes (default 2000; 0: no limit)");
  cmd->add_option("--max-edges", o->max_edges,
                  "Refuse pictures with more edges (default 4000; 0: no limit)");
  cmd->add_option("-o,--output", a->output, "Output file: .dot, .svg, .png or .pdf")->required();
  cmd->callback([a, o, cmd] {
    const Trace trace = read_trace(a->input);
    step_at(trace, a->step, a->input);  // before the assignment is checked against the trace
    const auto as = partition::load_assignment_if(a->assignment, trace, a->input);
    // Neither an aggregation nor a limit asked for: a step too large is drawn by kind.
    o->kinds_when_too_many =
        cmd->count("--collapse") + cmd->count("--max-nodes") + cmd->count("--max-edges") == 0;
    const std::string note =
        viz::draw_step(trace, a->input, a->step, as ? &*as : nullptr, *o, a->output);
    if (!note.empty()) std::fprintf(stderr, "tgraph viz: %s\n", name_fields(note, flag_of).c_str());
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
  cmd->callback([a] { viz::draw_timeline(a->input, a->range, a->output); });
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
    const auto as = partition::load_assignment_if(a->assignment, trace, a->input);
    viz::write_report(trace, a->input, as ? &*as : nullptr, a->step, a->compare, a->names,
                      partition::step_quotient, a->output);
    std::printf("report: %s\n", a->output.c_str());
  });
}

}  // namespace tgraph::app
