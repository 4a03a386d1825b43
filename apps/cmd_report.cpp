// SPDX-License-Identifier: MIT
// `tgraph report T.tgt [--replay R.json ...] [--compare C.json] [--assign A.tga] -o report.html`:
// one self-contained HTML page (viz::report_from_files, the assignment's quotient graph from
// partition::step_quotient, viz::report_html).
#include <cstdio>

#include "commands.hpp"
#include "tgraph/partition/assignment_io.hpp"
#include "tgraph/partition/evaluate.hpp"
#include "tgraph/viz/report.hpp"

namespace tgraph::app {

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
    std::optional<TraceAssignment> as;
    if (!a->assignment.empty()) as = partition::load_assignment(a->assignment, trace, a->input);
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
