// SPDX-License-Identifier: MIT
// `tgraph report T.tgt [--replay R.json ...] [--compare C.json] [--assign A.tga] -o report.html`:
// one self-contained HTML page (viz/report.hpp).
#include "commands.hpp"
#include "tgraph/partition/assignment_io.hpp"
#include "tgraph/viz/report.hpp"

namespace tgraph::app {

void add_report(CLI::App& app) {
  struct Options {
    std::string trace, compare, assignment, out;
    std::vector<std::string> replays;
    std::size_t step = 1;
  };
  auto o = std::make_shared<Options>();
  auto* cmd = app.add_subcommand("report", "Write a self-contained HTML report (tables, charts, timeline, graph)");
  cmd->add_option("trace", o->trace, "Trace file (.tgt)")->required();
  cmd->add_option("--replay", o->replays, "Replay timelines (replay --timeline) or measurements (replay --json)");
  cmd->add_option("--compare", o->compare, "Method x K comparison (tgraph compare --json)");
  cmd->add_option("--assign", o->assignment, "Assignment (.tga) colouring the step graph");
  cmd->add_option("--step", o->step, "Step drawn as a graph (default 1, or 0 for one-step traces)");
  cmd->add_option("-o,--output", o->out, "Output file (.html)")->required();
  cmd->callback([o] {
    const Trace trace = load_trace(o->trace);
    TraceAssignment a;
    if (!o->assignment.empty()) a = partition::load_assignment(o->assignment, trace, o->trace);
    const std::size_t step = trace.steps.size() > o->step ? o->step : 0;
    viz::ReportContent c = viz::report_content(trace, o->trace, a.steps.empty() ? nullptr : &a.steps[step],
                                               step, a.method);
    if (!o->compare.empty()) viz::add_compare_json(c, read_file_text(o->compare), o->compare);
    for (const std::string& r : o->replays) viz::add_replay_json(c, read_file_text(r), r);
    write_file_atomic(o->out, viz::report_html(c));
    std::printf("report: %s\n", o->out.c_str());
  });
}

}  // namespace tgraph::app
